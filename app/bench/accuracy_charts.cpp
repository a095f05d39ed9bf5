// app/bench/accuracy_charts.cpp — see accuracy_charts.hpp.
#include "bench/accuracy_charts.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <sstream>

#include "bench/sweep.hpp"
#include "sph2d/render/particle_export.hpp"
#include "sph2d/render/video.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace sph2d::cli::accuracy {
namespace {

const char* const kChartExtensions[] = {".gp", ".dat", ".svg", ".png"};

/// Okabe and Ito's colour-blind safe palette: one colour per solver of kSolvers, then the rest.
const char* const kColours[] = {"#E69F00", "#0072B2", "#009E73", "#CC79A7", "#D55E00", "#56B4E9", "#000000", "#F0E442"};
/// gnuplot's filled and open marks: circle, square, triangle, diamond, pentagon.
const int kFilled[] = {7, 5, 9, 13, 15}, kOpen[] = {6, 4, 8, 12, 14};
const int kWidth = 960, kHeight = 600;
/// The plot area, as shares of the canvas from its left and bottom (fixed: the labels are placed for it).
const double kLeft = 0.115, kRight = 0.80, kBottom = 0.095, kTop = 0.88;

/// `s` with only letters, digits and ".+-_" kept (others become '?'): safe inside any gnuplot string.
std::string plain(const std::string& s) {
  std::string o;
  for (char c : s) o += std::isalnum(static_cast<unsigned char>(c)) || std::strchr(".+-_", c) ? c : '?';
  return o.empty() ? "?" : o;
}

/// A particle count as a label: 800, 3.2k, 12.8k, 80k, 1.2M.
std::string countLabel(std::size_t n) {
  char b[32];
  if (n < 1000)
    std::snprintf(b, sizeof b, "%zu", n);
  else if (n < 1000000)
    std::snprintf(b, sizeof b, "%.3gk", double(n) / 1e3);
  else
    std::snprintf(b, sizeof b, "%.3gM", double(n) / 1e6);
  return b;
}

/// A point's label: its resolution (particles), and its floor when it has one.
std::string pointLabel(const Run& r) { return countLabel(r.particles) + (r.floor.empty() ? "" : " " + plain(r.floor)); }

/// The error axis's title: what the case measures, against what, in which unit (gnuplot's enhanced text).
std::string errorTitle(const std::string& name) {
  const std::string rho = "\xcf\x81", pi = "\xcf\x80";
  if (name == "pressure_profile_max_rel")
    return "error: worst deviation of the pressure profile from " + rho + "_0 g (H - y)\\n(share of " + rho + "_0 g H)";
  if (name == "surge_front_rms_Z")
    return "error: RMS of the surge front Z = x/a against\\nMartin and Moyce 1952  (column widths a)";
  if (name == "umax_ratio_rms") return "error: RMS of |u|_{max}/U against exp(-8" + pi + "^2 t/Re)\\n(share of U)";
  if (name == "u_rms_vs_series") return "error: RMS of u/u_c against the start-up series\\n(share of u_c)";
  std::string s = plain(name);
  std::replace(s.begin(), s.end(), '_', ' ');
  return "error: " + s;
}

/// Tick marks of a log axis over [lo, hi], as gnuplot's list ("0.1" 0.1, "1" 1, ...): the first of
/// the decades, 1-2-5, 1-2-3-5 and finer steps that gives 4 ticks or more (at most 10).
std::string logTics(double lo, double hi) {
  const std::vector<std::vector<double>> steps = {
      {1}, {1, 2, 5}, {1, 2, 3, 5}, {1, 1.5, 2, 3, 4, 5, 6, 8}, {1, 1.2, 1.5, 2, 2.5, 3, 3.5, 4, 5, 6, 7, 8, 9}};
  std::vector<double> best;
  for (const auto& m : steps) {
    std::vector<double> t;
    for (int e = int(std::floor(std::log10(lo))); e <= int(std::ceil(std::log10(hi))); ++e)
      for (double k : m) {
        const double v = k * std::pow(10.0, e);
        if (v >= lo && v <= hi) t.push_back(v);
      }
    if (t.size() > 10) break;
    best = t;
    if (t.size() >= 4) break;
  }
  if (best.empty()) return "autofreq";
  std::string s = "(";
  for (double v : best) {
    char b[64];
    std::snprintf(b, sizeof b, "%s\"%.3g\" %.3g", s.size() > 1 ? ", " : "", v, v);
    s += b;
  }
  return s + ")";
}

/// The case's title: "dam break" for dam_break.
std::string caseTitle(const std::string& caseName) {
  std::string s = plain(caseName);
  std::replace(s.begin(), s.end(), '_', ' ');
  return s;
}

std::string g(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

bool measured(const Run& r) {
  return r.status == "ok" && std::isfinite(r.error) && r.error > 0 && std::isfinite(r.wallPerSim) && r.wallPerSim > 0;
}

/// A run in a note: "pbf 80k ×2".
std::string shortName(const Run& r) {
  const int k = cflIndexOf(r.id);
  return plain(r.solver) + " " + pointLabel(r) + (k > 1 ? " \xc3\x97" + std::to_string(k) : "");
}

/// Waits for `pid`; "" when it exited 0, else what happened.
std::string waitFor(pid_t pid) {
  int status = 0;
  pid_t w;
  do w = ::waitpid(pid, &status, 0);
  while (w < 0 && errno == EINTR);
  if (w < 0) return std::string("waitpid: ") + std::strerror(errno);
  if (WIFEXITED(status)) return WEXITSTATUS(status) == 0 ? "" : "exit code " + std::to_string(WEXITSTATUS(status));
  return "killed by signal " + std::to_string(WTERMSIG(status));
}

/// Runs `gnuplot -c SCRIPT SVG PNG` (no shell, standard input /dev/null); "" when it succeeded.
std::string runGnuplot(const std::string& exe, const std::string& script, const std::string& svg,
                       const std::string& png) {
  std::vector<std::string> args = {exe, "-c", script, svg, png};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return "cannot start " + exe + ": " + std::strerror(rc);
  const std::string how = waitFor(pid);
  return how.empty() ? "" : exe + " " + script + ": " + how;
}

/// Where each point's label goes, in data coordinates (its left end, its middle height): of eight
/// places around the point, the one that covers the fewest labels placed before it, points and
/// space outside the plot, on axes over [x0, x1] × [y0, y1] (log) in the plot area above.
std::vector<std::pair<double, double>> placeLabels(const std::vector<const Run*>& pts, double x0, double x1, double y0,
                                                   double y1) {
  struct Box {
    double l, t, r, b;
  };
  const double L = kLeft * kWidth, R = kRight * kWidth, T = (1 - kTop) * kHeight, B = (1 - kBottom) * kHeight;
  const double lx0 = std::log10(x0), lx1 = std::log10(x1), ly0 = std::log10(y0), ly1 = std::log10(y1);
  auto px = [&](double v) { return L + (std::log10(v) - lx0) / (lx1 - lx0) * (R - L); };
  auto py = [&](double v) { return B - (std::log10(v) - ly0) / (ly1 - ly0) * (B - T); };
  auto overlap = [](const Box& a, const Box& b) {
    return std::max(0.0, std::min(a.r, b.r) - std::max(a.l, b.l)) *
           std::max(0.0, std::min(a.b, b.b) - std::max(a.t, b.t));
  };
  std::vector<Box> taken;  // the points' marks first, then each label placed
  for (const Run* p : pts)
    taken.push_back({px(p->wallPerSim) - 7, py(p->error) - 7, px(p->wallPerSim) + 7, py(p->error) + 7});
  std::vector<std::pair<double, double>> at;
  for (const Run* p : pts) {
    const double x = px(p->wallPerSim), y = py(p->error), w = 6.0 * double(pointLabel(*p).size()) + 2, h = 12;
    const double places[][2] = {{9, -8}, {9, 8},       {-9 - w, -8},  {-9 - w, 8},
                                {10, 0}, {-10 - w, 0}, {-w / 2, -15}, {-w / 2, 15}};
    Box best{};
    double bestScore = 1e300;
    for (std::size_t k = 0; k < std::size(places); ++k) {
      const Box c{x + places[k][0], y + places[k][1] - h / 2, x + places[k][0] + w, y + places[k][1] + h / 2};
      double score = 0.01 * double(k) + 2 * (w * h - overlap(c, Box{L, T, R, B}));
      for (const Box& o : taken) score += overlap(c, o);
      if (score < bestScore) bestScore = score, best = c;
    }
    taken.push_back(best);
    at.emplace_back(std::pow(10.0, lx0 + (best.l - L) / (R - L) * (lx1 - lx0)),
                    std::pow(10.0, ly0 + (B - (best.t + best.b) / 2) / (B - T) * (ly1 - ly0)));
  }
  return at;
}

}  // namespace

bool isChartFile(const std::string& name) {
  for (const char* c : kCases)
    for (const char* e : kChartExtensions)
      if (name == std::string(c) + e) return true;
  return false;
}

ChartText chartText(const std::vector<Run>& runs, const std::string& caseName) {
  std::vector<const Run*> pts, missing;
  for (const Run& r : runs)
    if (r.caseName == caseName) (measured(r) ? pts : missing).push_back(&r);
  if (pts.empty()) return {};
  std::vector<std::string> solvers;  // in the rows' order (the sweep's)
  for (const Run* r : pts)
    if (std::find(solvers.begin(), solvers.end(), r->solver) == solvers.end()) solvers.push_back(r->solver);
  // The Pareto front: the runs no other run beats in both error and cost, cheapest first.
  std::vector<const Run*> front;
  for (const Run* a : pts) {
    bool dominated = false;
    for (const Run* b : pts)
      dominated = dominated || (b->error <= a->error && b->wallPerSim <= a->wallPerSim &&
                                (b->error < a->error || b->wallPerSim < a->wallPerSim));
    if (!dominated) front.push_back(a);
  }
  std::stable_sort(front.begin(), front.end(),
                   [](const Run* a, const Run* b) { return a->wallPerSim < b->wallPerSim; });
  double x0 = 1e300, x1 = 0, y0 = 1e300, y1 = 0;
  bool twice = false;
  for (const Run* r : pts) {
    x0 = std::min(x0, r->wallPerSim), x1 = std::max(x1, r->wallPerSim);
    y0 = std::min(y0, r->error), y1 = std::max(y1, r->error);
    twice = twice || cflIndexOf(r->id) > 1;
  }
  const double xa = x0 / 1.5, xb = x1 * 1.8, ya = y0 / 1.3, yb = y1 * 1.3;  // the axes' ranges
  const std::vector<std::pair<double, double>> labelAt = placeLabels(pts, xa, xb, ya, yb);
  const std::string name = plain(caseName), gp = name + ".gp", dat = name + ".dat";

  std::ostringstream d;
  d << "# " << dat << ": the data of " << gp << " (sph2d bench accuracy), " << pts.size() << " runs of " << name
    << ".\n# Blocks (gnuplot's index), two blank lines apart: one per solver, then the Pareto front.\n"
    << "# Columns: wall s per simulated s, error (" << plain(pts[0]->errorName)
    << "), label (particles), CFL index (1: the solver's default CFL-type number, 2: twice it), run id,\n"
    << "# where the label goes (its left end, its middle; placed clear of the other labels and points).\n";
  auto row = [&](const Run* r) {
    const auto& [lx, ly] = labelAt[std::size_t(std::find(pts.begin(), pts.end(), r) - pts.begin())];
    d << g(r->wallPerSim) << ' ' << g(r->error) << " \"" << pointLabel(*r) << "\" " << std::max(1, cflIndexOf(r->id))
      << " \"" << plain(r->id) << "\" " << g(lx) << ' ' << g(ly) << "\n";
  };
  for (std::size_t k = 0; k < solvers.size(); ++k) {
    d << (k ? "\n\n" : "") << "# solver " << plain(solvers[k]) << "\n";
    for (const Run* r : pts)
      if (r->solver == solvers[k]) row(r);
  }
  d << "\n\n# Pareto front\n";
  for (const Run* r : front) row(r);

  std::string s;
  auto add = [&s](const std::string& line) { s += line + "\n"; };
  add("# " + gp + ": the chart of sph2d bench accuracy's " + caseTitle(caseName) + " case, what accuracy costs in");
  add("# time: error against wall seconds per simulated second, log-log, one series per solver (filled");
  add("# marks: the solver's default CFL-type number, open: twice it), each point labelled with its");
  add("# particle count, the Pareto front drawn. Its data: " + dat + " beside it.");
  add("#   gnuplot " + gp + "                 draws " + name + ".svg and " + name + ".png beside this file");
  add("#   gnuplot -c " + gp + " A.svg B.png   draws A.svg and B.png");
  add("me = \"" + gp + "\"");
  add("n = strlen(ARG0) - strlen(me)");
  add("dir = (n > 0 && ARG0[n+1:] eq me) ? ARG0[1:n] : \"\"");
  add("data = dir . \"" + dat + "\"");
  add("svg = ARGC >= 1 ? ARG1 : dir . \"" + name + ".svg\"");
  add("png = ARGC >= 2 ? ARG2 : dir . \"" + name + ".png\"");
  add("");
  add("set encoding utf8");
  add("set logscale xy");
  add("set xrange [" + g(xa) + ":" + g(xb) + "]");
  add("set yrange [" + g(ya) + ":" + g(yb) + "]");
  add("set xtics " + logTics(xa, xb));
  add("set ytics " + logTics(ya, yb));
  add("set lmargin at screen " + g(kLeft) + "; set rmargin at screen " + g(kRight));
  add("set bmargin at screen " + g(kBottom) + "; set tmargin at screen " + g(kTop));
  add("set xlabel \"cost: wall seconds per simulated second  (s/s)\"");
  add("set ylabel \"" + errorTitle(pts[0]->errorName) + "\"");
  add("set title \"" + caseTitle(caseName) +
      ": error against cost\\n{/*0.8 lower left is better; the grey line joins the Pareto front: the runs no other "
      "run beats in both}\"");
  add("set grid xtics ytics lc rgb \"#dddddd\" lw 1");
  add("set key outside right top vertical Left reverse noenhanced spacing 1.15 font \",10\"");
  if (!missing.empty()) {
    // Below the key, one run a line: the runs without a figure (the guard stopped them).
    const std::string why = missing[0]->status == "ok" ? "no figure" : plain(missing[0]->status);
    std::string list = "not drawn (" + why + "):";
    for (std::size_t k = 0; k < missing.size() && k < 8; ++k) list += "\\n" + shortName(*missing[k]);
    if (missing.size() > 8) list += "\\nand " + std::to_string(missing.size() - 8) + " more";
    add("set label 1 \"" + list + "\" at screen " + g(kRight + 0.02) +
        ", screen 0.4 left front font \",9\" noenhanced");
  }
  add("");
  add("set terminal svg size " + std::to_string(kWidth) + "," + std::to_string(kHeight) +
      " fixed enhanced font \"DejaVu Sans,12\" background rgb \"white\"");
  add("set output svg");
  const std::string frontIndex = "  data index " + std::to_string(solvers.size());
  add("plot \\");
  add(frontIndex + " using 1:2 with lines lw 8 lc rgb \"#a0909090\" title \"Pareto front\", \\");
  add(frontIndex + " using 1:2 with points pt 6 ps 2.6 lw 1.5 lc rgb \"#606060\" notitle, \\");
  for (std::size_t k = 0; k < solvers.size(); ++k) {
    const int at = indexOf(kSolvers, solvers[k]);
    const std::size_t c = at >= 0 ? std::size_t(at) : std::size(kSolvers) + k;
    const std::string colour = " lc rgb \"" + std::string(kColours[c % std::size(kColours)]) + "\"";
    const std::string filled = std::to_string(kFilled[c % std::size(kFilled)]);
    const std::string open = std::to_string(kOpen[c % std::size(kOpen)]), idx = "  data index " + std::to_string(k);
    add(idx + " using 1:($4 == 1 ? $2 : NaN) with points pt " + filled + " ps 1.4" + colour + " title \"" +
        plain(solvers[k]) + "\", \\");
    if (twice)
      add(idx + " using 1:($4 != 1 ? $2 : NaN) with points pt " + open + " ps 1.4 lw 2" + colour + " notitle, \\");
    add(idx + " using 6:7:3 with labels left font \",9\" tc" + colour.substr(3) + " notitle, \\");
  }
  if (twice) {
    add("  keyentry with points pt 7 ps 1.4 lc rgb \"#404040\" title \"CFL \xc3\x97"
        "1\", \\");
    add("  keyentry with points pt 6 ps 1.4 lw 2 lc rgb \"#404040\" title \"CFL \xc3\x97"
        "2\", \\");
  }
  s.resize(s.size() - 4);  // the last ", \"
  s += "\n";
  add("unset output");
  add("");
  add("if (strstrt(\" \" . GPVAL_TERMINALS . \" \", \" pngcairo \") > 0) {");
  add("  set terminal pngcairo size " + std::to_string(kWidth) + "," + std::to_string(kHeight) +
      " enhanced font \"DejaVu Sans,11\" background rgb \"white\"");
  add("} else {");
  add("  set terminal png size " + std::to_string(kWidth) + "," + std::to_string(kHeight) +
      " enhanced font \"DejaVuSans,10\" background rgb \"white\"");
  add("}");
  add("set output png");
  add("replot");
  add("unset output");
  return {s, d.str()};
}

std::string findGnuplot() { return findProgram("gnuplot"); }

ChartsDone writeCharts(const std::vector<Run>& runs, OutputJournal& journal, const std::string& out) {
  ChartsDone done;
  for (const char* c : kCases) {
    const ChartText t = chartText(runs, c);
    if (t.script.empty()) continue;
    for (const auto& [name, bytes] : {std::pair{std::string(c) + ".dat", t.data}, {std::string(c) + ".gp", t.script}}) {
      writeNoted(journal, out, name, bytes);
      done.written.push_back(name);
    }
    done.scripts.push_back(std::string(c) + ".gp");
  }
  if (done.scripts.empty()) return done;
  const std::string exe = findGnuplot();
  if (exe.empty()) {
    done.problem = kNoGnuplot;
    return done;
  }
  for (const std::string& script : done.scripts) {
    const std::string stem = script.substr(0, script.size() - 3);
    std::vector<std::pair<std::string, std::string>> files;  // name, temporary path
    for (const char* e : {".svg", ".png"}) {
      const std::string name = stem + e, temp = tempPathFor(out + "/" + name);
      journal.note(name, fs::path(temp).filename().string(), std::nullopt);
      files.emplace_back(name, temp);
    }
    // Absolute paths: gnuplot opens a name starting with '|' or '<' as a command and expands
    // '~', so a folder name (--out) never reaches it as the start of a path.
    std::string why = runGnuplot(exe, fs::absolute(out + "/" + script).string(), fs::absolute(files[0].second).string(),
                                 fs::absolute(files[1].second).string());
    for (const auto& [name, temp] : files)
      if (why.empty() && (!fs::is_regular_file(temp) || fs::file_size(temp) == 0))
        why = "gnuplot " + script + " wrote no " + name;
    if (!why.empty()) {
      for (const auto& f : files) ::unlink(f.second.c_str());
      done.problem = why;
      return done;
    }
    for (const auto& [name, temp] : files) {
      const auto h = hashFile(temp);
      if (!h) throw std::runtime_error("cannot read " + temp);
      journal.note(name, fs::path(temp).filename().string(), h);
      if (std::rename(temp.c_str(), (out + "/" + name).c_str()) != 0)
        throw std::runtime_error("cannot rename " + temp + " to " + out + "/" + name + ": " + std::strerror(errno));
      done.written.push_back(name);
    }
  }
  done.drawn = true;
  return done;
}

}  // namespace sph2d::cli::accuracy
