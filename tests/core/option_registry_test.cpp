// tests/core/option_registry_test.cpp: the option registry (src/core/option_registry.cpp) and the
// option tables of docs/problem-files.md. The docs are written by hand and checked here: a test
// fails when a registry key has no row in its table, a row names a key the registry does not
// have, or a row's type, default, range or nosnoc name differs from the registry's.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <fesd/error.hpp>
#include <fesd/ocp.hpp>
#include <fesd/options.hpp>
#include <fesd/problem_file.hpp>

#include "core/option_registry.hpp"
#include "io/option_target.hpp"

namespace fesd {
namespace {

using registry::Kind;
using registry::Option;
using registry::Table;
using registry::Use;

/// A default simulation problem and a default OCP problem, with their option targets (T_sim and T
/// set, as a file must).
struct Defaults {
  SimulationProblem sim;
  OcpProblem ocp;
  Defaults() {
    sim.T_sim = 1;
    ocp.ocp.T = 1;
  }
  registry::OptionTarget target(const Option& o) {
    return o.use == Use::Ocp ? io_detail::target_of(ocp) : io_detail::target_of(sim);
  }
};

bool contains(std::string_view haystack, std::string_view needle) {
  return haystack.find(needle) != std::string_view::npos;
}

/// "`name`", as the docs write keys and names.
std::string code(std::string_view name) {
  std::string s = "`";
  s.append(name);
  s.append("`");
  return s;
}

TEST(OptionRegistry, KeysAreUniqueAcrossTables) {
  // The command line accepts every key without its table, so a key names one option.
  std::set<std::string_view> seen;
  for (const Option& o : registry::all()) {
    EXPECT_TRUE(seen.insert(o.key).second) << o.key;
    if (!o.alias.empty()) {
      EXPECT_TRUE(seen.insert(o.alias).second) << o.alias;
    }
    EXPECT_FALSE(o.doc.empty()) << o.key;
    const bool scalar = o.kind != Kind::Input;
    EXPECT_EQ(o.get != nullptr, scalar) << o.key;
    EXPECT_EQ(o.set != nullptr, scalar) << o.key;
    EXPECT_EQ(!o.names.empty(), o.kind == Kind::Enum) << o.key;
  }
}

TEST(OptionRegistry, DefaultsValidate) {
  Defaults d;
  EXPECT_TRUE(validate(d.sim.options).empty());
  EXPECT_TRUE(validate(d.ocp.options).empty());
  for (Table t : registry::tables(Use::Both)) {
    for (const Option& o : registry::all()) {
      if (o.table != t || o.get == nullptr) continue;
      const registry::OptionTarget target = d.target(o);
      EXPECT_EQ(registry::check(o, target, o.get(target)), "") << registry::path_of(o);
    }
  }
}

/// Just outside each end of every bounded range: rejected with "<table>.<key> = <value>: must
/// be ...", by validate() and the OCP's rules alike.
TEST(OptionRegistry, EveryBoundIsRejected) {
  int checked = 0;
  for (const Option& o : registry::all()) {
    if (o.kind != Kind::Int && o.kind != Kind::Double) continue;
    const registry::Range& r = o.range;
    std::vector<double> outside{INFINITY, NAN};
    if (o.kind == Kind::Int) outside.clear();
    if (r.min > -registry::Range::kNone) outside.push_back(r.min_open ? r.min : r.min - 1);
    if (r.max < registry::Range::kNone) outside.push_back(r.max_open ? r.max : r.max + 1);
    for (double v : outside) {
      Defaults d;
      const registry::OptionTarget target = d.target(o);
      o.set(target, v);
      const std::vector<std::string> errors = registry::check(o.table, target);
      const std::string head =
          fmt::format("{} = {}:", registry::path_of(o), registry::format_value(o, v));
      ASSERT_FALSE(errors.empty()) << head;
      EXPECT_EQ(errors.front().rfind(head + " must be ", 0), 0u) << errors.front();
      ++checked;
    }
  }
  EXPECT_GE(checked, 30);
}

TEST(OptionRegistry, NamedRules) {
  DiscretizationOptions d;
  d.rk_scheme = RkScheme::LobattoIIIC;
  d.n_s = 1;
  d.N_FE = 1;
  EXPECT_EQ(validate(d), (std::vector<std::string>{
                             "discretization.n_s = 1: must be in 2..9 for lobatto_iiic",
                             "discretization.N_finite_elements = 1: FESD needs >= 2 finite "
                             "elements (with one there is no step size to move); use 2 or "
                             "use_fesd = false"}));
  HomotopyOptions h;
  h.sigma_0 = 0.1;
  h.sigma_N = 0.5;
  EXPECT_EQ(validate(h),
            (std::vector<std::string>{"homotopy.sigma_N = 0.5: must be <= sigma_0 = 0.1"}));
  EXPECT_EQ(registry::validate_simulation(0, 0),
            (std::vector<std::string>{"simulation.T_sim = 0: must be > 0",
                                      "simulation.N_sim = 0: must be >= 1"}));
}

// The homotopy's sigma schedule (HomotopyOptions::homotopy_update_rule): linear by default;
// nosnoc's superlinear rule max(sigma_N, min(slope sigma, sigma^exponent)) from sigma_0 = 1 to
// sigma_N = 1e-6 with slope 0.1 and exponent 1.5: 1, 0.1, 0.01, 1e-3, 10^-4.5, 1e-6.
TEST(OptionRegistry, HomotopyUpdateRules) {
  fesd::HomotopyOptions h;
  h.sigma_0 = 1.0;
  h.sigma_N = 1e-6;
  EXPECT_EQ(fesd::homotopy_length(h), 7);
  EXPECT_DOUBLE_EQ(fesd::next_sigma(h, 1e-3), 1e-4);
  EXPECT_DOUBLE_EQ(fesd::next_sigma(h, 1e-6), 1e-6);
  h.homotopy_update_rule = fesd::HomotopyUpdateRule::Superlinear;
  const std::vector<double> expected = {1.0, 0.1, 0.01, 1e-3, std::pow(10.0, -4.5), 1e-6};
  double sigma = h.sigma_0;
  for (std::size_t k = 1; k < expected.size(); ++k) {
    sigma = fesd::next_sigma(h, sigma);
    EXPECT_NEAR(sigma, expected[k], 1e-14 * expected[k]) << k;
  }
  EXPECT_EQ(fesd::homotopy_length(h), 6);
  EXPECT_NEAR(fesd::final_sigma(h), 1e-6, 1e-20);
  EXPECT_DOUBLE_EQ(fesd::next_sigma(h, 10.0), 1.0);  // above 1 the slope is the smaller step
  h.homotopy_update_exponent = 2.0;                  // sigma^2 < 0.1 sigma below 0.1
  EXPECT_DOUBLE_EQ(fesd::next_sigma(h, 0.01), 1e-4);
  EXPECT_TRUE(fesd::validate(h).empty());
  h.homotopy_update_exponent = 1.0;
  EXPECT_FALSE(fesd::validate(h).empty());
  h.homotopy_update_exponent = 11.0;
  EXPECT_FALSE(fesd::validate(h).empty());
  // An exponent next to 1 with a slow slope: superlinear only far below sigma_N, so as many NLPs
  // as the linear rule (2751), down to sigma_N; and no count is cut short at 1000.
  h.sigma_N = 1e-12;
  h.homotopy_update_slope = 0.99;
  h.homotopy_update_exponent = 1.0001;
  fesd::HomotopyOptions linear = h;
  linear.homotopy_update_rule = fesd::HomotopyUpdateRule::Linear;
  EXPECT_EQ(fesd::homotopy_length(linear), 2751);
  EXPECT_EQ(fesd::homotopy_length(h), 2751);
  EXPECT_NEAR(fesd::final_sigma(h), 1e-12, 1e-24);
  fesd::HomotopyUpdateRule rule{};
  for (const char* name : {"linear", "LINEAR"}) {
    ASSERT_TRUE(fesd::parse(name, rule)) << name;
    EXPECT_EQ(rule, fesd::HomotopyUpdateRule::Linear);
  }
  ASSERT_TRUE(fesd::parse("SUPERLINEAR", rule));
  EXPECT_EQ(fesd::to_string(rule), "superlinear");
  EXPECT_FALSE(fesd::parse("quadratic", rule));
}

TEST(OptionRegistry, EnumNamesComeFromTheEnumsOwnTable) {
  for (const Option& o : registry::all()) {
    if (o.kind != Kind::Enum) continue;
    for (std::size_t i = 0; i < o.names.size(); ++i) {
      EXPECT_EQ(o.parse_name(o.names[i]), static_cast<int>(i)) << o.key;
      EXPECT_EQ(registry::format_value(o, static_cast<double>(i)), o.names[i]);
    }
    EXPECT_EQ(o.parse_name("no_such_name"), -1) << o.key;
  }
  EXPECT_EQ(to_string(TerminalConstraint::L1), "ell_1");
  EXPECT_EQ(to_string(OcpInitialization::Simulation), "simulation");
  RkScheme s = RkScheme::RadauIIA;
  EXPECT_TRUE(parse("LOBATTO_IIIC", s));  // nosnoc's spelling
  EXPECT_EQ(s, RkScheme::LobattoIIIC);
}

// ---- docs/problem-files.md ----------------------------------------------------------------------

/// The cells of a markdown table row ("| a | b \| c |" -> {"a", "b \| c"}).
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  for (std::size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '|' && line[i - 1] != '\\') {
      const auto b = cell.find_first_not_of(' '), e = cell.find_last_not_of(' ');
      out.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
      cell.clear();
    } else {
      cell += line[i];
    }
  }
  return out;
}

std::string without_backticks(std::string s) {
  s.erase(std::remove(s.begin(), s.end(), '`'), s.end());
  return s;
}

/// One table of the docs: column name -> index, and key -> row cells.
struct DocTable {
  std::map<std::string, std::size_t> column;
  std::map<std::string, std::vector<std::string>> rows;
  const std::string& cell(const std::string& key, const std::string& col) const {
    return rows.at(key).at(column.at(col));
  }
};

/// The first table after the heading that names `[table]`.
DocTable read_doc_table(const std::vector<std::string>& lines, std::string_view table) {
  DocTable t;
  const std::string name = code(fmt::format("[{}]", table));
  std::size_t i = 0;
  while (i < lines.size() && !(lines[i].rfind("## ", 0) == 0 && contains(lines[i], name))) ++i;
  while (i < lines.size() && lines[i].rfind("| key |", 0) != 0) ++i;
  if (i >= lines.size()) return t;
  const std::vector<std::string> header = cells(lines[i]);
  for (std::size_t c = 0; c < header.size(); ++c) t.column[header[c]] = c;
  for (i += 2; i < lines.size() && lines[i].rfind("|", 0) == 0; ++i) {
    const std::vector<std::string> row = cells(lines[i]);
    std::stringstream keys(row.at(0));
    for (std::string k; std::getline(keys, k, ',');) {
      k = without_backticks(k);
      const std::size_t first = k.find_first_not_of(' ');
      if (first != std::string::npos) t.rows[k.substr(first)] = row;
    }
  }
  return t;
}

std::string type_word(Kind k) {
  switch (k) {
    case Kind::Int:
      return "integer";
    case Kind::Double:
      return "number";
    case Kind::Bool:
      return "boolean";
    default:
      return "string";
  }
}

/// Whether a default cell states `v` of option `o` (numbers compared as numbers).
bool states_default(const std::string& cell, const Option& o, double v) {
  switch (o.kind) {
    case Kind::Int:
    case Kind::Double:
      try {
        return std::stod(without_backticks(cell)) == v;
      } catch (...) {
        return false;
      }
    case Kind::Bool:
      return contains(cell, v != 0 ? "`true`" : "`false`");
    default:
      return contains(cell, code(fmt::format("\"{}\"", registry::format_value(o, v))));
  }
}

TEST(OptionDocs, TablesMatchTheRegistry) {
  std::ifstream in(std::string(FESD_SOURCE_DIR) + "/docs/problem-files.md");
  ASSERT_TRUE(in);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);

  Defaults d;
  for (Table table : registry::tables(Use::Both)) {
    const std::string name(registry::to_string(table));
    const DocTable doc = read_doc_table(lines, name);
    ASSERT_FALSE(doc.rows.empty()) << "docs/problem-files.md: no table of [" << name << "]";
    for (const char* col : {"key", "type", "default", "range"})
      ASSERT_TRUE(doc.column.count(col)) << "[" << name << "] has no column '" << col << "'";
    // Every row is a registry key ([ipopt] also passes any other key to IPOPT).
    for (const auto& [key, row] : doc.rows) {
      if (key == "*any other key*") continue;
      EXPECT_NE(registry::find(table, key), nullptr)
          << "docs/problem-files.md [" << name << "] documents '" << key
          << "', which the option registry does not have";
    }
    for (const Option& o : registry::all()) {
      if (o.table != table) continue;
      const std::string where = fmt::format("docs/problem-files.md [{}] {}", name, o.key);
      if (!doc.rows.count(std::string(o.key))) {
        ADD_FAILURE() << where << ": no row for this registry option";
        continue;
      }
      const std::string key(o.key);
      if (doc.column.count("nosnoc")) {
        const std::string& cell = doc.cell(key, "nosnoc");
        if (o.nosnoc.empty())
          EXPECT_TRUE(cell.rfind("-", 0) == 0 || cell.rfind("—", 0) == 0) << where << ": " << cell;
        else
          EXPECT_TRUE(contains(cell, code(o.nosnoc))) << where << ": " << cell;
      }
      if (o.kind == Kind::Input) continue;
      EXPECT_EQ(doc.cell(key, "type"), type_word(o.kind)) << where;
      const std::string& def = doc.cell(key, "default");
      if (o.required) {
        EXPECT_EQ(def.rfind("required", 0), 0u) << where << ": " << def;
      } else if (o.use == Use::Ocp) {
        EXPECT_TRUE(states_default(def, o, o.get(io_detail::target_of(d.ocp))))
            << where << ": " << def;
      } else {
        const double sim = o.get(io_detail::target_of(d.sim));
        EXPECT_TRUE(states_default(def, o, sim)) << where << ": " << def;
        if (o.use == Use::Both) {
          const double ocp = o.get(io_detail::target_of(d.ocp));
          if (ocp != sim) {
            EXPECT_TRUE(states_default(def, o, ocp)) << where << " (OCP): " << def;
          }
        }
      }
      const std::string range = without_backticks(doc.cell(key, "range"));
      if (o.kind == Kind::Enum) {
        for (std::string_view n : o.names)
          EXPECT_TRUE(contains(doc.cell(key, "range"), code(n))) << where << ": " << n;
      } else if (o.kind != Kind::Bool) {
        EXPECT_EQ(range.rfind(registry::range_text(o), 0), 0u)
            << where << ": the range cell '" << range << "' does not start with '"
            << registry::range_text(o) << "'";
      }
    }
  }
}

}  // namespace
}  // namespace fesd
