// app/bench/accuracy_charts.hpp — the charts of `sph2d bench accuracy`, drawn by gnuplot.
//
// Per case with measured runs the bench writes CASE.gp, a gnuplot script, and CASE.dat, its
// data: error (in the case's own measure) against wall seconds per simulated second, log-log,
// one series per solver (filled marks: the CFL-type number at its default, open: twice it),
// each point labelled with its particle count (and floor, surge_long), the Pareto front drawn
// (the runs no other run beats in both error and cost). `gnuplot CASE.gp` draws CASE.svg and
// CASE.png beside the script, from any folder (the script finds its data by its own path);
// `gnuplot -c CASE.gp A.svg B.png` draws into A.svg and B.png.
//
// When gnuplot is on PATH the bench runs it on each script: a child process without a shell,
// its arguments the script's and the temporary files' paths, writing to PATH.tmpPID names
// noted in the folder's journal first, renamed once gnuplot exited 0: the charts are whole or
// absent. Every text of the rows that reaches a script is stripped to letters, digits and
// ".+-_" first: a row of a CSV cannot inject gnuplot commands.
#pragma once

#include <string>
#include <vector>

#include "bench/accuracy_report.hpp"
#include "output/output_dir.hpp"

namespace sph2d::cli::accuracy {

/// The chart files of every case: CASE.gp, CASE.dat, CASE.svg, CASE.png.
bool isChartFile(const std::string& name);

/// A case's chart as text: the gnuplot script and its data ("" when the case has no
/// measured run, nothing to draw).
struct ChartText {
  std::string script, data;
};
ChartText chartText(const std::vector<Run>& runs, const std::string& caseName);

/// ChartsDone::problem when gnuplot is not installed.
inline const char* const kNoGnuplot = "gnuplot is not on PATH";

/// The path of `gnuplot` on PATH, or "" when it is not installed.
std::string findGnuplot();

/// What writeCharts did.
struct ChartsDone {
  std::vector<std::string> written;  ///< the files written, in order
  std::vector<std::string> scripts;  ///< the scripts written (CASE.gp)
  bool drawn = false;                ///< gnuplot drew every script
  std::string problem;               ///< why not ("": drawn, or nothing to draw)
};

/// Writes CASE.gp and CASE.dat for every case of `runs` with a measured run into `out`, each
/// noted in `journal` first, then, when gnuplot is on PATH, runs it on each to draw CASE.svg
/// and CASE.png. A gnuplot that fails leaves no chart of that case and stops the drawing
/// (problem says why). Throws std::runtime_error when a file cannot be written.
ChartsDone writeCharts(const std::vector<Run>& runs, OutputJournal& journal, const std::string& out);

}  // namespace sph2d::cli::accuracy
