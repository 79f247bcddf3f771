// src/io/gnuplot.hpp: running gnuplot on a script for the plot writers (plot.cpp for integrator
// results, ocp_plot.cpp for OCP results). The data go inline in the script (gnuplot data blocks),
// the script goes to gnuplot's standard input: no temporary files. Internal to src/io.
#pragma once
#include <string>
#include <string_view>
#include <vector>

namespace fesd::io_detail {

/// Locale-independent %.17g; gnuplot reads NaN as an undefined point.
std::string gp_number(double v);
/// A gnuplot single-quoted string (line breaks become spaces).
std::string gp_string(std::string_view s);
/// `names[i]` where given and non-empty, else prefix + (i + 1): "x1", "u2".
std::vector<std::string> names_or_default(const std::vector<std::string>& names, std::size_t n,
                                          std::string_view prefix);
/// The "set terminal" line for the path's extension (.png or .svg, case-insensitive) and the
/// picture size; throws IoError for any other extension or a path with a line break.
std::string terminal_for(const std::string& path, int width, int height);
/// Writes the plot: checks that gnuplot is on PATH and the file can be created, runs gnuplot on
/// `script` (which sets the output to `path`), and removes a partial file on failure. Throws
/// IoError with gnuplot's last error lines.
void run_plot_script(const std::string& path, const std::string& script);

}  // namespace fesd::io_detail
