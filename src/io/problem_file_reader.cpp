// src/io/problem_file_reader.cpp: the parts of problem-file reading that simulation and optimal
// control files share (see problem_file_reader.hpp). Every check here has a line in
// docs/problem-files.md.
#include "io/problem_file_reader.hpp"

#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace fesd::io_detail {
namespace {

// Names the expression language reserves (src/model/expression.hpp).
constexpr std::array<std::string_view, 13> kReservedNames{
    "sin", "cos", "tan", "exp", "log", "sqrt", "tanh", "abs", "sinh", "cosh", "atan", "pow", "pi"};

constexpr std::array<std::string_view, 13> kModelKeys{
    "x", "u", "p", "c", "S", "F", "g", "x0", "subsystem", "z", "z0", "g_z", "f_alpha"};
constexpr std::array<std::string_view, 4> kSubsystemKeys{"c", "S", "g", "F"};

std::string lower(std::string_view s) {
  std::string r(s);
  for (char& ch : r)
    if (ch >= 'A' && ch <= 'Z') ch = static_cast<char>(ch - 'A' + 'a');
  return r;
}

/// Optimal-string-alignment distance (insertions, deletions, substitutions, transpositions).
int edit_distance(std::string_view a, std::string_view b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::vector<int>> d(n + 1, std::vector<int>(m + 1, 0));
  for (std::size_t i = 0; i <= n; ++i) d[i][0] = static_cast<int>(i);
  for (std::size_t j = 0; j <= m; ++j) d[0][j] = static_cast<int>(j);
  for (std::size_t i = 1; i <= n; ++i)
    for (std::size_t j = 1; j <= m; ++j) {
      const int cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[n][m];
}

bool before(const toml::source_region& a, const toml::source_region& b) {
  return a.begin.line != b.begin.line ? a.begin.line < b.begin.line
                                      : a.begin.column < b.begin.column;
}

void check_names(const Reader& r,
                 const std::vector<std::pair<std::string, const toml::node*>>& names,
                 std::string_view path, std::string_view kind, std::set<std::string>& seen,
                 bool t_allowed) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto& [name, node] = names[i];
    const std::string p = index(path, i);
    if (!is_identifier(name))
      r.fail(node->source(), p,
             fmt::format("invalid {} name (expected an identifier [A-Za-z_][A-Za-z0-9_]*, got "
                         "\"{}\")",
                         kind, expr::shorten(name)));
    if (std::find(kReservedNames.begin(), kReservedNames.end(), name) != kReservedNames.end())
      r.fail(node->source(), p,
             fmt::format("'{}' is reserved by the expression language (functions sin cos tan exp "
                         "log sqrt tanh abs sinh cosh atan pow and the constant pi); choose "
                         "another {} name",
                         name, kind));
    if (name == "t" && !t_allowed)
      r.fail(node->source(), p,
             fmt::format("'t' is the time; only a state may be named t (got a {} named t)", kind));
    if (!seen.insert(name).second)
      r.fail(node->source(), p,
             fmt::format("duplicate name '{}' (names must be unique across x, u, p and z)",
                         expr::shorten(name)));
  }
}

Eigen::MatrixXd read_sign_matrix(const Reader& r, const toml::node& n, std::string_view path,
                                 int n_c) {
  const toml::array& rows = r.array(n, path, "an array of rows of +1/-1");
  if (rows.empty()) r.fail(n.source(), path, "no rows (expected one row of +1/-1 per region)");
  Eigen::MatrixXd S(static_cast<Eigen::Index>(rows.size()), n_c);
  std::set<std::vector<int>> seen;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string rp = index(path, i);
    const toml::array& row = r.array(rows[i], rp, "a row of +1/-1");
    if (static_cast<int>(row.size()) != n_c)
      r.fail(rows[i].source(), rp,
             fmt::format("wrong length (expected {} entries, one per switching function in c, "
                         "got {})",
                         n_c, row.size()));
    std::vector<int> signs;
    for (std::size_t j = 0; j < row.size(); ++j) {
      const std::string ep = index(rp, j);
      const double v = r.number(row[j], ep);
      if (v != 1.0 && v != -1.0)
        r.fail(row[j].source(), ep, fmt::format("bad sign (expected 1 or -1, got {})", v));
      S(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = v;
      signs.push_back(v > 0 ? 1 : -1);
    }
    if (!seen.insert(signs).second)
      r.fail(rows[i].source(), rp, "repeats an earlier row (each region needs its own sign row)");
  }
  return S;
}

RawSubsystem read_subsystem(const Reader& r, const toml::table& t, std::string_view path,
                            const Symbols& sym, bool by_alpha = false) {
  RawSubsystem out;
  const toml::node* c = t.get("c");
  const toml::node* S = t.get("S");
  const toml::node* g = t.get("g");
  const toml::node* F = t.get("F");
  if (c != nullptr && g != nullptr)
    r.fail(g->source(), path,
           "both c and g given (expected either switching functions c, with an optional sign "
           "matrix S, or indicator functions g)");
  if (c == nullptr && g == nullptr)
    r.fail(t.source(), path,
           "missing regions (expected switching functions c = [...], with an optional sign matrix "
           "S, or indicator functions g = [...])");
  if (S != nullptr && c == nullptr)
    r.fail(S->source(), join(path, "S"),
           "a sign matrix needs switching functions c (with indicator functions g, give no S)");
  if (by_alpha) {  // the general inclusion f_alpha (read by read_model_spec) instead of F
    if (F != nullptr)
      r.fail(F->source(), join(path, "F"),
             "given both f_alpha and region-wise F (expected one of them: f_alpha(x, alpha, u, p) "
             "in the Heaviside step form, or one vector field per region)");
    if (c == nullptr)
      r.fail(g->source(), join(path, "g"),
             "f_alpha needs switching functions c (alpha_j belongs to c_j), not indicator "
             "functions g");
  } else if (F == nullptr)
    r.fail(t.source(), path,
           "missing key 'F' (expected one vector field per region, each an array of n_x "
           "expressions)");

  if (c != nullptr) {
    const std::string cp = join(path, "c");
    const toml::array& a = r.array(*c, cp, "an array of expressions");
    if (a.empty()) r.fail(c->source(), cp, "empty (expected at least one switching function)");
    for (std::size_t i = 0; i < a.size(); ++i) {
      out.expressions.c.push_back(r.expression(a[i], index(cp, i), sym.all));
      check_no_controls(r, out.expressions.c.back(), a[i], index(cp, i), sym,
                        "a switching function");
    }
    const int n_c = static_cast<int>(a.size());
    if (S != nullptr) {
      out.S = read_sign_matrix(r, *S, join(path, "S"), n_c);
      out.n_f = static_cast<int>(out.S.rows());
    } else {
      if (n_c > 10)
        r.fail(c->source(), cp,
               fmt::format("{} switching functions give 2^{} regions (expected at most 10 without "
                           "a sign matrix; give S with the regions you need)",
                           n_c, n_c));
      out.n_f = 1 << n_c;
    }
  } else {
    const std::string gp = join(path, "g");
    const toml::array& a = r.array(*g, gp, "an array of expressions");
    if (a.empty()) r.fail(g->source(), gp, "empty (expected one indicator function per region)");
    for (std::size_t i = 0; i < a.size(); ++i) {
      out.expressions.g.push_back(r.expression(a[i], index(gp, i), sym.all));
      check_no_controls(r, out.expressions.g.back(), a[i], index(gp, i), sym,
                        "an indicator function");
    }
    out.n_f = static_cast<int>(a.size());
  }

  if (by_alpha) return out;
  const std::string fp = join(path, "F");
  const toml::array& fields = r.array(*F, fp, "an array of vector fields, one per region");
  const std::string region_source =
      c != nullptr ? (S != nullptr ? "one per row of S" : "one per row of the default S, 2^n_c")
                   : "one per indicator function in g";
  if (static_cast<int>(fields.size()) != out.n_f)
    r.fail(F->source(), fp,
           fmt::format("wrong number of vector fields (expected {}, {}, got {})", out.n_f,
                       region_source, fields.size()));
  const std::size_t n_x = sym.x.size();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::string rp = index(fp, i);
    const toml::array& field = r.array(fields[i], rp, "an array of n_x expressions");
    if (field.size() != n_x)
      r.fail(fields[i].source(), rp,
             fmt::format("wrong length (expected {} expressions, one per state, got {})", n_x,
                         field.size()));
    std::vector<expr::Expression> f;
    for (std::size_t j = 0; j < field.size(); ++j)
      f.push_back(r.expression(field[j], index(rp, j), sym.all));
    out.expressions.F.push_back(std::move(f));
  }
  return out;
}

/// model.f_alpha: n_x expressions of x, t, u, p, z and alpha_1 .. alpha_{n_c} (the Heaviside step
/// form's general inclusion; docs/problem-files.md).
void read_f_alpha(const Reader& r, const toml::node& n, const Symbols& sym, RawSubsystem& s) {
  const std::string path = "model.f_alpha";
  const std::size_t n_c = s.expressions.c.size();
  std::vector<std::string> symbols = sym.all;
  for (std::size_t j = 1; j <= n_c; ++j) {
    const std::string a = fmt::format("alpha_{}", j);
    if (std::find(sym.all.begin(), sym.all.end(), a) != sym.all.end())
      r.fail(
          n.source(), path,
          fmt::format("the name '{}' is taken (f_alpha reads alpha_j, j = 1 .. n_c = {}, for the "
                      "switching functions c; rename the state, control, parameter or "
                      "algebraic variable)",
                      a, n_c));
    symbols.push_back(a);
  }
  const toml::array& a = r.array(n, path, "an array of n_x expressions");
  if (a.size() != sym.x.size())
    r.fail(n.source(), path,
           fmt::format("wrong length (expected {} expressions, one per state, got {})",
                       sym.x.size(), a.size()));
  for (std::size_t i = 0; i < a.size(); ++i)
    s.expressions.f_alpha.push_back(r.expression(a[i], index(path, i), symbols));
}

bool uses_symbol(const RawSubsystem& s, int index) {
  const auto any = [&](const std::vector<expr::Expression>& list) {
    return std::any_of(list.begin(), list.end(),
                       [&](const expr::Expression& e) { return e.depends_on(index); });
  };
  if (any(s.expressions.c) || any(s.expressions.g) || any(s.expressions.f_alpha)) return true;
  return std::any_of(s.expressions.F.begin(), s.expressions.F.end(), any);
}

}  // namespace

// ---- small helpers ----------------------------------------------------------------------------

std::string join(std::string_view path, std::string_view key) {
  return path.empty() ? std::string(key) : fmt::format("{}.{}", path, key);
}
std::string index(std::string_view path, std::size_t i) {
  return fmt::format("{}[{}]", path, i);
}

std::string describe(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: {
      std::string s = n.as_string()->get();
      if (s.size() > 40) s = s.substr(0, 37) + "...";
      return fmt::format("string \"{}\"", s);
    }
    case toml::node_type::integer:
      return fmt::format("integer {}", n.as_integer()->get());
    case toml::node_type::floating_point:
      return fmt::format("float {}", n.as_floating_point()->get());
    case toml::node_type::boolean:
      return fmt::format("boolean {}", n.as_boolean()->get());
    case toml::node_type::array:
      return fmt::format("an array of {}", n.as_array()->size());
    case toml::node_type::table:
      return "a table";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    default:
      return "nothing";
  }
}

std::string format_number(double v) {
  return fmt::format("{}", v);
}

std::string count(std::size_t n, std::string_view noun) {
  return fmt::format("{} {}{}", n, noun, n == 1 ? "" : "s");
}

bool is_identifier(std::string_view s) {
  if (s.empty()) return false;
  const auto alpha = [](char ch) {
    return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || ch == '_';
  };
  if (!alpha(s[0])) return false;
  return std::all_of(s.begin() + 1, s.end(),
                     [&](char ch) { return alpha(ch) || (ch >= '0' && ch <= '9'); });
}

std::vector<std::pair<const toml::key*, const toml::node*>> in_file_order(const toml::table& t) {
  std::vector<std::pair<const toml::key*, const toml::node*>> entries;
  for (auto&& [k, v] : t) entries.emplace_back(&k, &v);
  std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    return before(a.first->source(), b.first->source());
  });
  return entries;
}

std::string key_hint(std::string_view key, std::span<const std::string_view> valid,
                     std::string_view all) {
  // Keys by meaning (lower case -> the file key, hinted where that key is valid): nosnoc's names
  // (MATLAB and Python), the paper's symbols, and the other kind of problem's name of a key.
  static constexpr std::pair<std::string_view, std::string_view> kAliases[] = {
      {"n_fe", "N_finite_elements"},
      {"nfe", "N_finite_elements"},
      {"nfe_list", "N_finite_elements"},
      {"n_elements", "N_finite_elements"},
      {"num_fe", "N_finite_elements"},
      {"max_homotopy_steps", "N_homotopy"},
      {"max_iter_homotopy", "N_homotopy"},
      {"comp_tol", "complementarity_tol"},
      {"terminal_time", "T_sim"},
      {"terminal_time", "T"},
      // [simulation] T_sim, N_sim, u against [ocp] T, N_stages, u_guess.
      {"t", "T_sim"},
      {"tf", "T_sim"},
      {"tf", "T"},
      {"t_sim", "T"},
      {"n_sim", "N_stages"},
      {"u", "u_guess"},
      {"u_guess", "u"},
      {"tol_ipopt", "tol"},
      {"irk_scheme", "rk_scheme"},
      {"cross_comp", "cross_comp_mode"},
      {"g_ind", "g"},
      {"g_indicator", "g"},
      {"g_stewart", "g"},
      {"p_global", "p"},
      // [ocp]: nosnoc's MATLAB and Python spellings, and fesd's C++ field names.
      {"u0", "u_guess"},
      {"n_stg", "N_stages"},
      {"n_ctrl", "N_stages"},
      {"t_ctrl", "T"},
      {"f_terminal", "f_q_T"},
      {"g_path_lb", "lbg_path"},
      {"g_path_ub", "ubg_path"},
      {"g_terminal_lb", "lbg_terminal"},
      {"g_terminal_ub", "ubg_terminal"},
      {"rho_terminal_p", "rho_terminal"},
      {"terminal_constraint", "relax_terminal_constraint"},
  };
  const std::string k = lower(key);
  std::vector<std::pair<int, std::string_view>> near;
  for (std::string_view v : valid) {
    const std::string lv = lower(v);
    int d = edit_distance(k, lv);
    for (const auto& [alias, target] : kAliases)
      if (alias == k && target == v) d = 0;
    if (k.size() >= 3 && lv.size() >= 3 &&
        (lv.find(k) != std::string::npos || k.find(lv) != std::string::npos))
      d = std::min(d, 1);
    const int threshold = std::max<int>(1, std::min<int>(3, static_cast<int>(k.size()) / 3 + 1));
    if (d <= threshold) near.emplace_back(d, v);
  }
  // Only the nearest ones; among equally near keys, those of similar length first.
  if (!near.empty()) {
    const int best = std::min_element(near.begin(), near.end())->first;
    std::erase_if(near, [&](const auto& e) { return e.first > best; });
  }
  const auto length_gap = [&](std::string_view v) {
    return std::abs(static_cast<int>(v.size()) - static_cast<int>(k.size()));
  };
  std::stable_sort(near.begin(), near.end(), [&](const auto& a, const auto& b) {
    return length_gap(a.second) < length_gap(b.second);
  });
  std::string list;
  if (near.empty()) {
    for (std::string_view v : valid) list += (list.empty() ? "" : ", ") + std::string(v);
    return fmt::format("({}: {})", all, list);
  }
  const std::size_t n = std::min<std::size_t>(near.size(), 3);
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) list += i + 1 == n ? " or " : ", ";
    list += fmt::format("'{}'", near[i].second);
  }
  return fmt::format("(did you mean {}?)", list);
}

std::string read_problem_text(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw ProblemFileError(
        fmt::format("{}: cannot read problem file ({})", path,
                    std::filesystem::exists(path, ec) ? "not a regular file" : "no such file"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ProblemFileError(fmt::format("{}: cannot open problem file", path));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ProblemFileError(fmt::format("{}: error while reading problem file", path));
  return text.str();
}

toml::table parse_toml(std::string_view text, std::string_view source_name) {
  try {
    return toml::parse(text, std::string(source_name));
  } catch (const toml::parse_error& e) {
    throw ProblemFileError(fmt::format("{}:{}:{}: TOML syntax error: {}", source_name,
                                       e.source().begin.line, e.source().begin.column,
                                       e.description()));
  }
}

// ---- [model] ----------------------------------------------------------------------------------

void check_no_controls(const Reader& r, const expr::Expression& e, const toml::node& n,
                       std::string_view path, const Symbols& sym, std::string_view what) {
  for (std::size_t j = 0; j < sym.u.size(); ++j)
    if (e.depends_on(sym.first_u() + static_cast<int>(j)))
      r.fail(n.source(), path,
             fmt::format("{} cannot depend on controls (expected a function of x and p, got "
                         "control '{}' in \"{}\")",
                         what, sym.u[j], expr::shorten(e.text())));
  if (sym.z_control.empty()) return;
  for (std::size_t j = 0; j < sym.z.size(); ++j)
    if (e.depends_on(sym.first_z() + static_cast<int>(j)))
      r.fail(n.source(), path,
             fmt::format("{} cannot depend on controls (expected a function of x and p, got "
                         "algebraic variable '{}' in \"{}\", and g_z reads control '{}')",
                         what, sym.z[j], expr::shorten(e.text()), sym.z_control));
}

bool ModelSpec::uses_time() const {
  if (sym.time_index < 0) return false;
  if (std::any_of(g_z.begin(), g_z.end(),
                  [&](const expr::Expression& e) { return e.depends_on(sym.time_index); }))
    return true;
  return std::any_of(subsystems.begin(), subsystems.end(),
                     [&](const RawSubsystem& s) { return uses_symbol(s, sym.time_index); });
}

ModelSpec read_model_spec(const Reader& r, const toml::table& root) {
  const toml::node* model_node = root.get("model");
  if (model_node == nullptr)
    r.fail(toml::source_region{}, "model",
           "missing table [model] (expected x, x0, F and either c or g)");
  const toml::table& model = r.table(*model_node, "model");
  r.check_keys(model, kModelKeys, "model");

  ModelSpec spec;
  spec.table = &model;
  Symbols& sym = spec.sym;

  // Names.
  std::set<std::string> seen;
  const toml::node* x_node = model.get("x");
  if (x_node == nullptr)
    r.fail(model.source(), "model",
           "missing key 'x' (expected the state names, e.g. x = [\"x1\"])");
  const auto x_names = r.names(*x_node, "model.x");
  if (x_names.empty())
    r.fail(x_node->source(), "model.x", "no states (expected at least one state name)");
  check_names(r, x_names, "model.x", "state", seen, true);
  std::vector<std::pair<std::string, const toml::node*>> u_names;
  if (const toml::node* n = model.get("u")) u_names = r.names(*n, "model.u");
  check_names(r, u_names, "model.u", "control", seen, false);
  std::vector<std::pair<std::string, const toml::node*>> p_names;
  if (const toml::node* n = model.get("p")) {
    const toml::table* pt = n->as_table();
    if (pt == nullptr)
      r.wrong_type(*n, "model.p", "a table of name = value, e.g. { omega = 6.28 }");
    for (const auto& [k, v] : in_file_order(*pt)) {
      p_names.emplace_back(k->str(), v);
      spec.p_values.push_back(r.number(*v, join("model.p", k->str())));
    }
  }
  check_names(r, p_names, "model.p", "parameter", seen, false);
  std::vector<std::pair<std::string, const toml::node*>> z_names;
  const toml::node* z_node = model.get("z");
  if (z_node != nullptr) {
    z_names = r.names(*z_node, "model.z");
    if (z_names.empty())
      r.fail(z_node->source(), "model.z",
             "no algebraic variables (expected at least one name, or no key z)");
  }
  check_names(r, z_names, "model.z", "algebraic variable", seen, false);

  for (const auto& n : x_names) sym.x.push_back(n.first);
  for (const auto& n : u_names) sym.u.push_back(n.first);
  for (const auto& n : p_names) sym.p.push_back(n.first);
  for (const auto& n : z_names) sym.z.push_back(n.first);
  sym.all = sym.x;
  if (std::find(sym.x.begin(), sym.x.end(), "t") == sym.x.end()) {
    sym.time_index = static_cast<int>(sym.all.size());
    sym.all.push_back("t");
  }
  sym.all.insert(sym.all.end(), sym.u.begin(), sym.u.end());
  sym.all.insert(sym.all.end(), sym.p.begin(), sym.p.end());
  sym.all.insert(sym.all.end(), sym.z.begin(), sym.z.end());

  // Algebraic equations g_z(x, u, p, z) = 0 and Newton's start z0.
  const toml::node* g_z_node = model.get("g_z");
  const toml::node* z0_node = model.get("z0");
  if (z_node == nullptr) {
    if (g_z_node != nullptr)
      r.fail(g_z_node->source(), "model.g_z",
             "algebraic equations without algebraic variables (expected their names, z = [...])");
    if (z0_node != nullptr)
      r.fail(z0_node->source(), "model.z0",
             "a guess of algebraic variables, but there are none (expected their names, z = "
             "[...], and equations g_z = [...])");
  } else {
    const int n_z = static_cast<int>(sym.z.size());
    if (g_z_node == nullptr)
      r.fail(z_node->source(), "model",
             fmt::format("missing key 'g_z' (expected {}, the algebraic equations g_z(x, u, p, "
                         "z) = 0 of z)",
                         count(static_cast<std::size_t>(n_z), "expression")));
    const toml::array& a = r.array(*g_z_node, "model.g_z", "an array of expressions");
    if (static_cast<int>(a.size()) != n_z)
      r.fail(g_z_node->source(), "model.g_z",
             fmt::format("wrong length (expected {}, one per algebraic variable in z, got {})",
                         count(static_cast<std::size_t>(n_z), "expression"), a.size()));
    const int first_z = sym.first_z();
    for (std::size_t i = 0; i < a.size(); ++i) {
      spec.g_z.push_back(r.expression(a[i], index("model.g_z", i), sym.all));
      for (std::size_t j = 0; j < sym.u.size() && sym.z_control.empty(); ++j)
        if (spec.g_z.back().depends_on(sym.first_u() + static_cast<int>(j)))
          sym.z_control = sym.u[j];
    }
    bool reads_z = false;
    for (const expr::Expression& e : spec.g_z)
      for (int j = 0; j < n_z; ++j) reads_z = reads_z || e.depends_on(first_z + j);
    if (!reads_z)
      r.fail(g_z_node->source(), "model.g_z",
             "no equation reads z (expected g_z(x, u, p, z) = 0 to determine z)");
    spec.z0 = Eigen::VectorXd::Zero(n_z);
    if (z0_node != nullptr)
      spec.z0 = r.vector(*z0_node, "model.z0", n_z, "one per algebraic variable in z");
  }

  // Regions and vector fields: directly in [model] or in [[model.subsystem]].
  if (const toml::node* sub = model.get("subsystem")) {
    if (const toml::node* fa = model.get("f_alpha"))
      r.fail(fa->source(), "model.f_alpha",
             "needs the switching functions c directly in [model] (one subsystem; alpha_j belongs "
             "to c_j), not [[model.subsystem]]");
    for (std::string_view k : kSubsystemKeys)
      if (const toml::node* direct = model.get(k))
        r.fail(direct->source(), join("model", k),
               "given both in [model] and as [[model.subsystem]] (expected c/S/g/F either "
               "directly in [model] or in every [[model.subsystem]], not both)");
    const toml::array* list = sub->as_array();
    if (list != nullptr && list->empty())
      r.fail(sub->source(), "model.subsystem", "empty (expected at least one subsystem)");
    if (list == nullptr || !list->is_array_of_tables())
      r.wrong_type(*sub, "model.subsystem", "an array of tables ([[model.subsystem]])");
    for (std::size_t k = 0; k < list->size(); ++k) {
      const std::string path = index("model.subsystem", k);
      const toml::table& t = *(*list)[k].as_table();
      r.check_keys(t, kSubsystemKeys, path);
      spec.subsystems.push_back(read_subsystem(r, t, path, sym));
    }
  } else {
    const toml::node* fa = model.get("f_alpha");
    spec.subsystems.push_back(read_subsystem(r, model, "model", sym, fa != nullptr));
    if (fa != nullptr) read_f_alpha(r, *fa, sym, spec.subsystems.back());
  }
  return spec;
}

BuiltModel build_model(const Reader& r, ModelSpec spec, bool has_clock, double t0) {
  const toml::table& model = *spec.table;
  const Symbols& sym = spec.sym;
  std::vector<RawSubsystem>& subsystems = spec.subsystems;
  const int n_x_user = static_cast<int>(sym.x.size());
  const int n_x = n_x_user + (has_clock ? 1 : 0);
  if (has_clock) {
    const expr::Expression one = expr::Expression::parse("1", sym.all, "clock t' = 1");
    const expr::Expression zero = expr::Expression::parse("0", sym.all, "clock t' = 0");
    for (std::size_t k = 0; k < subsystems.size(); ++k)
      for (auto& field : subsystems[k].expressions.F) field.push_back(k == 0 ? one : zero);
    if (!subsystems[0].expressions.f_alpha.empty())
      subsystems[0].expressions.f_alpha.push_back(one);
  }
  const int n_alpha = subsystems[0].expressions.f_alpha.empty()
                          ? 0
                          : static_cast<int>(subsystems[0].expressions.c.size());

  // x0.
  const toml::node* x0_node = model.get("x0");
  if (x0_node == nullptr)
    r.fail(model.source(), "model",
           fmt::format("missing key 'x0' (expected the initial state, {})",
                       count(static_cast<std::size_t>(n_x_user), "number")));
  BuiltModel out;
  out.x0 = r.vector(*x0_node, "model.x0", n_x_user, "one per state in x");
  if (has_clock) {
    out.x0.conservativeResize(n_x);
    out.x0[n_x_user] = t0;
  }  // without a clock, t0 has no effect

  // The Pss.
  PssDims dims;
  dims.n_x = n_x;
  dims.n_u = static_cast<int>(sym.u.size());
  dims.n_p = static_cast<int>(sym.p.size());
  std::vector<ExpressionSubsystem> expressions;
  for (RawSubsystem& s : subsystems) {
    if (!s.expressions.c.empty())
      dims.subsystems.push_back(Subsystem::from_c(static_cast<int>(s.expressions.c.size()), s.S));
    else
      dims.subsystems.push_back(Subsystem::from_g(static_cast<int>(s.expressions.g.size())));
    expressions.push_back(std::move(s.expressions));
  }
  ExpressionLayout layout;
  layout.n_x = n_x;
  layout.n_x_slots = n_x_user + (sym.time_index >= 0 ? 1 : 0);
  layout.n_u = dims.n_u;
  layout.n_p = dims.n_p;
  layout.n_alpha = n_alpha;
  if (!sym.z.empty())
    layout.algebraic = std::make_shared<const AlgebraicEquations>(
        layout.n_x_slots + layout.n_u + layout.n_p, std::move(spec.g_z), spec.z0);
  out.algebraic = layout.algebraic;
  try {
    out.model = make_expression_pss(std::move(dims), layout, std::move(expressions));
  } catch (const InvalidModel& e) {
    throw InvalidModel(fmt::format("{}: {}", r.at(model.source()), e.what()));
  }
  out.model.state_names = sym.x;
  if (has_clock) out.model.state_names.push_back("t");
  out.model.control_names = sym.u;
  out.model.parameter_names = sym.p;
  out.model.algebraic_names = sym.z;
  out.p = Eigen::Map<const Eigen::VectorXd>(spec.p_values.data(),
                                            static_cast<Eigen::Index>(spec.p_values.size()));
  out.model.p_default = out.p;
  return out;
}

// ---- options ----------------------------------------------------------------------------------

double read_option(const Reader& r, const registry::Option& o, const toml::node& n) {
  const std::string path = registry::path_of(o);
  switch (o.kind) {
    case registry::Kind::Int:
      return r.integer(n, path);
    case registry::Kind::Double:
      return r.number(n, path);
    case registry::Kind::Bool:
      return r.boolean(n, path) ? 1 : 0;
    case registry::Kind::Enum: {
      const std::string name = r.string(n, path);
      const int i = o.parse_name(name);
      if (i < 0)
        throw InvalidOption(
            fmt::format("{}: {}: {}", r.at(n.source()), path, registry::unknown_name(o, name)));
      return i;
    }
    case registry::Kind::Input:
      break;
  }
  throw std::logic_error("read_option: " + path + " is read by the loader");
}

void check_table_keys(const Reader& r, const toml::table& t, registry::Table table,
                      registry::Use kind) {
  if (table == registry::Table::Ipopt) return;  // any other key is IPOPT's
  r.check_keys(t, registry::keys(table, kind), registry::to_string(table));
}

void check_required_key(const Reader& r, const toml::table& t, registry::Table table) {
  const registry::Option* o = registry::required_option(table);
  if (o == nullptr || t.get(o->key) != nullptr) return;
  r.fail(t.source(), registry::to_string(table),
         fmt::format("missing key '{}' (expected {}, {})", o->key, o->doc,
                     registry::expected_text(*o)));
}

void fail_missing_table(const Reader& r, registry::Table table) {
  const registry::Option* o = registry::required_option(table);
  r.fail(toml::source_region{}, registry::to_string(table),
         o == nullptr ? fmt::format("missing table [{}]", registry::to_string(table))
                      : fmt::format("missing table [{}] (expected at least {}, {})",
                                    registry::to_string(table), o->key, o->doc));
}

void read_option_table(const Reader& r, const toml::table& t, registry::Table table,
                       registry::Use kind, const registry::OptionTarget& target,
                       std::vector<std::pair<std::string, std::string>>& extra,
                       std::span<const std::string_view> read_elsewhere) {
  for (const registry::Option& o : registry::all()) {
    if (o.table != table || o.set == nullptr || !registry::has(o, kind)) continue;
    if (std::find(read_elsewhere.begin(), read_elsewhere.end(), o.key) != read_elsewhere.end())
      continue;
    if (const toml::node* n = t.get(o.key)) o.set(target, read_option(r, o, *n));
  }
  if (table != registry::Table::Ipopt) return;
  for (const auto& [k, v] : in_file_order(t)) {
    if (registry::find(table, k->str()) != nullptr) continue;
    extra.emplace_back(k->str(), ipopt_value(r, *v, join("ipopt", k->str())));
  }
}

std::string ipopt_value(const Reader& r, const toml::node& n, std::string_view path) {
  if (const auto* s = n.as_string()) return s->get();
  if (const auto* i = n.as_integer()) return fmt::format("{}", i->get());
  if (n.is_floating_point()) return format_number(r.number(n, path));
  if (const auto* b = n.as_boolean()) return b->get() ? "yes" : "no";
  r.wrong_type(n, path, "a string, number or boolean (an IPOPT option value)");
}

std::string_view message_key(std::string_view message) {
  const std::size_t end = std::min(message.find(" = "), message.find(": "));
  return end == std::string_view::npos ? std::string_view{} : message.substr(0, end);
}

std::string located(const Reader& r, const toml::table& root,
                    const std::vector<std::string>& messages) {
  std::string msg;
  for (const std::string& e : messages) {
    std::string where = r.file();
    const std::string_view key = message_key(e);
    if (!key.empty()) {
      const auto node = root.at_path(key);
      if (node) where = r.at(node.node()->source());
    }
    msg += (msg.empty() ? "" : "; ") + fmt::format("{}: {}", where, e);
  }
  return msg;
}

void throw_validation_errors(const Reader& r, const toml::table& root,
                             const std::vector<std::string>& errors) {
  throw InvalidOption(located(r, root, errors));
}

// ---- overrides --------------------------------------------------------------------------------

std::optional<int> parse_int(std::string_view s) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  long long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    return std::nullopt;
  return static_cast<int>(v);
}

std::optional<double> parse_double(std::string_view s) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

OverrideArg parse_override_arg(std::string_view key, std::string_view value, registry::Use kind) {
  OverrideArg a;
  while (!key.empty() && key.front() == '-') key.remove_prefix(1);
  a.value = trim(value);
  // "--p omega=2" as written on the command line; "--n_s = 3" for every other key.
  a.head = fmt::format("--{}{}{}", key, key == "p" || key == "model.p" ? " " : " = ", a.value);
  if (const std::size_t dot = key.find('.'); dot != std::string_view::npos) {
    a.table = key.substr(0, dot);
    key = key.substr(dot + 1);
    std::vector<std::string_view> tables{"model"};  // x0 and p (set_model_override)
    for (registry::Table t : registry::tables(kind)) tables.push_back(registry::to_string(t));
    if (std::find(tables.begin(), tables.end(), a.table) == tables.end())
      override_error(a.head,
                     fmt::format("unknown table '{}' {}", a.table, key_hint(a.table, tables)));
  }
  a.key = key;
  for (const registry::Option& o : registry::all()) {
    if (!registry::has(o, kind) || (!a.table.empty() && registry::to_string(o.table) != a.table))
      continue;
    if (o.key == key || (!o.alias.empty() && o.alias == key)) {
      a.option = &o;
      a.key = o.key;
    }
  }
  return a;
}

bool set_scalar_override(const OverrideArg& a, const registry::OptionTarget& target) {
  if (a.option == nullptr || a.option->set == nullptr) return false;
  a.option->set(target, override_value(*a.option, a.value, a.head));
  return true;
}

void set_ipopt_option(std::vector<std::pair<std::string, std::string>>& extra, std::string_view key,
                      const std::string& value) {
  const auto it =
      std::find_if(extra.begin(), extra.end(), [&](const auto& kv) { return kv.first == key; });
  if (it != extra.end())
    it->second = value;
  else
    extra.emplace_back(std::string(key), value);
}

Eigen::VectorXd override_vector(const std::string& head, std::string_view value, int n,
                                std::string_view path, std::string_view what) {
  std::vector<double> v;
  std::string_view rest = value;
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const auto d = parse_double(trim(rest.substr(0, comma)));
    if (!d) override_error(head, fmt::format("expected comma-separated numbers, {}", what));
    if (!std::isfinite(*d))
      override_error(
          head, fmt::format("{} = {}: must be finite", index(path, v.size()), format_number(*d)));
    v.push_back(*d);
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
  }
  if (static_cast<int>(v.size()) != n)
    override_error(head, fmt::format("wrong length (expected {}, {}, got {})",
                                     count(static_cast<std::size_t>(n), "number"), what, v.size()));
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

bool set_model_override(const OverrideArg& a, Pss& model, bool has_clock, Eigen::VectorXd& x0,
                        Eigen::VectorXd& p) {
  if (!a.table.empty() && a.table != "model") return false;
  if (a.key == "x0") {
    const int n_x_user = model.n_x() - (has_clock ? 1 : 0);  // the clock keeps its start value
    x0.head(n_x_user) =
        override_vector(a.head, a.value, n_x_user, "model.x0", "one per state in model.x");
    return true;
  }
  return set_parameter_override(a, model.parameter_names, p, model.p_default);
}

bool set_parameter_override(const OverrideArg& a, const std::vector<std::string>& names,
                            Eigen::VectorXd& p, Eigen::VectorXd& p_default) {
  if ((!a.table.empty() && a.table != "model") || a.key != "p") return false;
  const std::size_t eq = a.value.find('=');
  const std::string name = trim(std::string_view(a.value).substr(0, eq));
  if (eq == std::string::npos || name.empty())
    override_error(a.head,
                   fmt::format("expected NAME=VALUE, a parameter of model.p and its value (e.g. "
                               "--p {}=2.5)",
                               names.empty() ? "k" : names.front()));
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    if (names.empty())
      override_error(a.head, fmt::format("unknown parameter '{}' (the model has no parameters: "
                                         "model.p is empty)",
                                         name));
    const std::vector<std::string_view> valid(names.begin(), names.end());
    override_error(a.head, fmt::format("unknown parameter '{}' {}", name,
                                       key_hint(name, valid, "parameters in model.p")));
  }
  const std::string path = join("model.p", name);
  const std::string text = trim(std::string_view(a.value).substr(eq + 1));
  const auto d = parse_double(text);
  if (!d) override_error(a.head, fmt::format("{}: expected a number, got \"{}\"", path, text));
  if (!std::isfinite(*d))
    override_error(a.head, fmt::format("{} = {}: must be finite", path, format_number(*d)));
  const auto i = static_cast<Eigen::Index>(it - names.begin());
  p[i] = *d;
  p_default[i] = *d;
  return true;
}

void unknown_override(const OverrideArg& a, registry::Use kind, const Pss& model) {
  if (a.option != nullptr && !a.option->overridable)
    override_error(a.head, fmt::format("unknown option '{}' (expressions and bounds can only be "
                                       "set in the file)",
                                       a.key));
  const bool model_key = std::find(kModelKeys.begin(), kModelKeys.end(), a.key) != kModelKeys.end();
  if (model_key && (a.table == "model" || (a.table.empty() && a.key != "u" && a.key != "x")))
    override_error(a.head, fmt::format("unknown option '{}' (model.{} can only be set in the file; "
                                       "the [model] overrides are x0 and p)",
                                       a.key, a.key));
  const std::vector<std::string>& parameters = model.parameter_names;
  if (a.table.empty() && std::find(parameters.begin(), parameters.end(), a.key) != parameters.end())
    override_error(a.head, fmt::format("unknown option '{}' ('{}' is a parameter of model.p: write "
                                       "--p {}={})",
                                       a.key, a.key, a.key, a.value));
  std::vector<std::string_view> valid;
  if (a.table.empty() || a.table == "model") valid = {"x0", "p"};
  for (const registry::Option& o : registry::all()) {
    if (!o.overridable || !registry::has(o, kind)) continue;
    if (!a.table.empty() && registry::to_string(o.table) != a.table) continue;
    valid.push_back(o.key);
    if (!o.alias.empty()) valid.push_back(o.alias);
  }
  override_error(a.head, fmt::format("unknown option '{}' {}", a.key, key_hint(a.key, valid)));
}

void override_error(const std::string& head, std::string_view what) {
  throw InvalidOption(fmt::format("{}: {}", head, what));
}

std::string trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return std::string(s);
}

double override_value(const registry::Option& o, const std::string& value,
                      const std::string& head) {
  switch (o.kind) {
    case registry::Kind::Int: {
      const auto i = parse_int(value);
      if (!i) override_error(head, "expected an integer");
      return *i;
    }
    case registry::Kind::Double: {
      const auto d = parse_double(value);
      if (!d) override_error(head, "expected a number");
      if (!std::isfinite(*d)) override_error(head, "must be finite");
      return *d;
    }
    case registry::Kind::Bool:
      if (value == "1" || value == "true") return 1;
      if (value == "0" || value == "false") return 0;
      override_error(head,
                     fmt::format("expected a boolean (1, 0, true or false, got \"{}\")", value));
    case registry::Kind::Enum: {
      const int i = o.parse_name(value);
      if (i < 0) override_error(head, registry::unknown_name(o, value));
      return i;
    }
    case registry::Kind::Input:
      break;
  }
  throw std::logic_error("override_value: " + registry::path_of(o) + " is set by the loader");
}

void throw_override_errors(const OverrideArg& a, const std::vector<std::string>& errors) {
  const std::string own =
      a.option != nullptr && a.option->set != nullptr ? registry::path_of(*a.option) : "";
  std::string msg;
  for (const std::string& e : errors) {
    std::string_view text = e;
    if (!own.empty() && message_key(text) == own) {
      const std::size_t colon = text.find(": ");
      if (colon != std::string_view::npos) text.remove_prefix(colon + 2);
    }
    msg += (msg.empty() ? "" : "; ") + std::string(text);
  }
  override_error(a.head, msg);
}

}  // namespace fesd::io_detail
