// The charts of `sph2d bench accuracy`, drawn by gnuplot (app/bench/accuracy_charts.hpp): what
// the SVG says (axis titles, one label per run in its solver's colour), that the PNG is one of
// the chart's size with the solvers' colours in it, the Pareto front of the data, a run without
// gnuplot (exit 0, the CSV and the script written, one line saying how to draw them), the
// script drawn by hand from another folder and by benchmarks/plot_accuracy.sh, charts that a
// later run replaces or removes, and a CSV whose names cannot reach gnuplot as commands.
// Needs gnuplot (Debian's gnuplot-nox; .ci/setup.sh installs it).
#include <doctest/doctest.h>

#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "app_util.hpp"

using namespace sph2d::apptest;

namespace {

void requireGnuplot() {
  const Result g = runShell("gnuplot --version");
  INFO(g.out);
  REQUIRE_MESSAGE(g.code == 0, "gnuplot is missing: install Debian's `gnuplot-nox` (.ci/setup.sh lists it)");
}

/// A text element of an SVG: its characters (entities decoded, tspans joined) and the fill of
/// the nearest element around it that has one.
struct SvgText {
  std::string text, fill;
};

/// An XML document read strictly enough to say it is well formed: one root, every element
/// closed in order, attributes quoted. `why` is "" when it is.
struct Xml {
  std::string why, root;
  std::map<std::string, std::string> rootAttributes;
  std::vector<SvgText> texts;
};

std::string decode(const std::string& s) {
  std::string o;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '&') {
      o += s[i];
      continue;
    }
    const std::size_t end = s.find(';', i);
    const std::string e = s.substr(i + 1, end - i - 1);
    static const std::map<std::string, std::string> named = {
        {"amp", "&"}, {"lt", "<"}, {"gt", ">"}, {"quot", "\""}, {"apos", "'"}};
    if (named.count(e))
      o += named.at(e);
    else
      o += '?';  // a numeric reference: a character the checks below do not look for
    i = end;
  }
  return o;
}

Xml readXml(const std::string& s) {
  Xml x;
  struct Open {
    std::string name;
    std::map<std::string, std::string> attributes;
  };
  std::vector<Open> stack;
  std::string text;
  std::size_t i = 0;
  int roots = 0;
  auto fail = [&](const std::string& why) {
    x.why = why + " at byte " + std::to_string(i);
    return x;
  };
  while (i < s.size()) {
    if (s[i] != '<') {
      const std::size_t next = s.find('<', i);
      const std::string chunk = s.substr(i, next == std::string::npos ? std::string::npos : next - i);
      if (stack.empty() && chunk.find_first_not_of(" \t\r\n") != std::string::npos)
        return fail("text outside the root");
      text += decode(chunk);
      i = next == std::string::npos ? s.size() : next;
      continue;
    }
    auto skipTo = [&](const std::string& end) {
      const std::size_t at = s.find(end, i);
      i = at == std::string::npos ? std::string::npos : at + end.size();
      return at != std::string::npos;
    };
    if (s.compare(i, 4, "<!--") == 0 || s.compare(i, 2, "<?") == 0 || s.compare(i, 9, "<![CDATA[") == 0) {
      if (!skipTo(s[i + 1] == '?' ? "?>" : s[i + 2] == '-' ? "-->" : "]]>")) return fail("an unclosed <! or <?");
      continue;
    }
    const bool closing = s[i + 1] == '/';
    std::size_t j = i + (closing ? 2 : 1);
    std::string name;
    while (j < s.size() && (std::isalnum(static_cast<unsigned char>(s[j])) || std::strchr(":_-.", s[j])))
      name += s[j++];
    if (name.empty()) return fail("a tag without a name");
    Open open{name, {}};
    bool empty = false;
    for (;;) {
      while (j < s.size() && std::isspace(static_cast<unsigned char>(s[j]))) ++j;
      if (j >= s.size()) return fail("an unclosed tag <" + name);
      if (s[j] == '>') break;
      if (s.compare(j, 2, "/>") == 0) {
        empty = true;
        ++j;
        break;
      }
      if (closing) return fail("attributes in </" + name);
      const std::size_t eq = s.find('=', j);
      if (eq == std::string::npos || (s[eq + 1] != '"' && s[eq + 1] != '\'')) return fail("an unquoted attribute");
      const std::size_t close = s.find(s[eq + 1], eq + 2);
      if (close == std::string::npos) return fail("an unclosed attribute value");
      open.attributes[s.substr(j, eq - j)] = decode(s.substr(eq + 2, close - eq - 2));
      j = close + 1;
    }
    i = j + 1;
    if (closing) {
      if (stack.empty() || stack.back().name != name) return fail("</" + name + "> closes nothing open");
      if (name == "text") {
        std::string fill;
        for (auto it = stack.rbegin(); it != stack.rend() && fill.empty(); ++it)
          if (it->attributes.count("fill")) fill = it->attributes.at("fill");
        x.texts.push_back({text, fill});
      }
      stack.pop_back();
      continue;
    }
    if (stack.empty()) {
      if (++roots > 1) return fail("a second root <" + name + ">");
      x.root = name;
      x.rootAttributes = open.attributes;
    }
    if (name == "text") text.clear();
    if (!empty) stack.push_back(open);
  }
  if (!stack.empty()) return fail("<" + stack.back().name + "> never closed");
  if (roots != 1) return fail("no root element");
  return x;
}

/// The rows of an accuracy.csv, each by column name.
std::vector<std::map<std::string, std::string>> csvRows(const std::string& path) {
  std::istringstream in(readText(path));
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = csvCells(line);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = csvCells(line + ",");  // a last empty cell is a cell
    std::map<std::string, std::string> r;
    for (std::size_t k = 0; k < header.size() && k < f.size(); ++k) r[header[k]] = f[k];
    rows.push_back(r);
  }
  return rows;
}

/// The run ids of a CASE.dat's last block, the Pareto front (each row's second quoted cell).
std::set<std::string> frontIds(const std::string& dat) {
  std::set<std::string> ids;
  const std::size_t at = dat.find("# Pareto front\n");
  std::istringstream in(at == std::string::npos ? "" : dat.substr(at));
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') {
      std::vector<std::size_t> quotes;
      for (std::size_t k = 0; k < line.size(); ++k)
        if (line[k] == '"') quotes.push_back(k);
      REQUIRE(quotes.size() == 4);
      ids.insert(line.substr(quotes[2] + 1, quotes[3] - quotes[2] - 1));
    }
  return ids;
}

std::string attribute(const Xml& x, const std::string& name) {
  const auto it = x.rootAttributes.find(name);
  return it == x.rootAttributes.end() ? std::string() : it->second;
}

bool exists(const std::string& p) { return std::filesystem::exists(p); }

const char* kSweep = "bench accuracy --levels 2 --cases poiseuille --solvers game,wcsph --threads 1";

}  // namespace

TEST_CASE("bench accuracy draws each case's chart with gnuplot: an SVG with axis titles and a label per run, a PNG") {
  requireGnuplot();
  const std::string dir = freshDir("charts_drawn");
  const Result r = run(std::string(kSweep) + " --out " + q(dir) + " --assets " + q(SPH2D_ASSETS));
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("charts not drawn") == std::string::npos);
  CHECK(r.out.find("poiseuille.gp, poiseuille.svg, poiseuille.png into") != std::string::npos);
  const auto rows = csvRows(dir + "/accuracy.csv");
  REQUIRE(rows.size() == 8);  // 2 solvers × 2 CFL numbers × 2 resolutions
  CHECK(!anyTemporary(dir));

  // The SVG: well formed, 960 × 600, the titles of both axes with their units, the case's title.
  const Xml svg = readXml(readText(dir + "/poiseuille.svg"));
  REQUIRE_MESSAGE(svg.why.empty(), svg.why);
  CHECK(svg.root == "svg");
  CHECK(attribute(svg, "xmlns") == "http://www.w3.org/2000/svg");
  CHECK(attribute(svg, "width") == "960");
  CHECK(attribute(svg, "height") == "600");
  std::multiset<std::string> texts;
  for (const SvgText& t : svg.texts) texts.insert(t.text);
  CHECK(texts.count("cost: wall seconds per simulated second  (s/s)") == 1);
  CHECK(texts.count("error: RMS of u/uc against the start-up series") == 1);  // u_c: c a subscript
  CHECK(texts.count("(share of uc)") == 1);
  CHECK(texts.count("poiseuille: error against cost") == 1);
  CHECK(texts.count("Pareto front") == 1);
  CHECK(texts.count("game") == 1);
  CHECK(texts.count("wcsph") == 1);
  // Each run's resolution, its particle count, in its solver's colour: one label per run.
  const std::map<std::string, std::string> colour = {{"game", "rgb(213,94,0)"}, {"wcsph", "rgb(0,114,178)"}};
  std::map<std::pair<std::string, std::string>, int> wanted, got;
  for (const auto& row : rows) ++wanted[{row.at("particles"), colour.at(row.at("solver"))}];
  for (const SvgText& t : svg.texts)
    if (wanted.count({t.text, t.fill})) ++got[{t.text, t.fill}];
  CHECK(wanted.size() == 4);  // 80 and 200 particles, two solvers
  CHECK(got == wanted);

  // The PNG: a valid PNG of the chart's size, the solvers' colours in its marks.
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgba;
  sph2d::readPng(dir + "/poiseuille.png", w, h, rgba);
  CHECK(w == 960);
  CHECK(h == 600);
  auto pixels = [&](int red, int green, int blue) {
    int n = 0;
    for (std::size_t p = 0; p + 3 < rgba.size(); p += 4)
      n += rgba[p] == red && rgba[p + 1] == green && rgba[p + 2] == blue;
    return n;
  };
  CHECK(pixels(213, 94, 0) > 50);   // game
  CHECK(pixels(0, 114, 178) > 50);  // wcsph
  CHECK(pixels(255, 255, 255) > w * h / 2);

  // The Pareto front of the data: the runs no other run beats in both error and cost.
  std::set<std::string> front;
  for (const auto& a : rows) {
    bool beaten = false;
    const double ea = std::stod(a.at("error")), ca = std::stod(a.at("wall_s_per_sim_s"));
    for (const auto& b : rows) {
      const double eb = std::stod(b.at("error")), cb = std::stod(b.at("wall_s_per_sim_s"));
      beaten = beaten || (eb <= ea && cb <= ca && (eb < ea || cb < ca));
    }
    if (!beaten) front.insert(a.at("run_id"));
  }
  CHECK(!front.empty());
  CHECK(frontIds(readText(dir + "/poiseuille.dat")) == front);

  // A later run replaces the charts it wrote (its journal lists them); one without gnuplot
  // removes them: a chart never stays beside a CSV it was not drawn from.
  const Result again = run("bench accuracy --charts-only " + q(dir + "/accuracy.csv"));
  INFO(again.out);
  CHECK(again.code == 0);
  CHECK(readXml(readText(dir + "/poiseuille.svg")).why.empty());
  const Result bare =
      run(std::string(kSweep) + " --quick --out " + q(dir) + " --assets " + q(SPH2D_ASSETS), "PATH=/nonexistent");
  INFO(bare.out);
  CHECK(bare.code == 0);
  CHECK(!exists(dir + "/poiseuille.svg"));
  CHECK(!exists(dir + "/poiseuille.png"));
  CHECK(exists(dir + "/poiseuille.gp"));
}

TEST_CASE("bench accuracy without gnuplot exits 0 with the CSV and the scripts, and says how to draw the charts") {
  requireGnuplot();  // to draw them afterwards
  const std::string dir = freshDir("charts_no_gnuplot");
  const Result r =
      run(std::string(kSweep) + " --quick --out " + q(dir) + " --assets " + q(SPH2D_ASSETS), "PATH=/nonexistent");
  INFO(r.out);
  REQUIRE(r.code == 0);
  REQUIRE(csvRows(dir + "/accuracy.csv").size() == 2);
  CHECK(csvRows(dir + "/accuracy.csv")[0].at("status") == "ok");
  const std::string gp = readText(dir + "/poiseuille.gp"), dat = readText(dir + "/poiseuille.dat");
  CHECK(gp.find("set xlabel \"cost: wall seconds per simulated second  (s/s)\"") != std::string::npos);
  CHECK(gp.find("data = dir . \"poiseuille.dat\"") != std::string::npos);
  CHECK(dat.find("\"80\" 1 \"poiseuille-game-80-cfl1\"") != std::string::npos);
  CHECK(!exists(dir + "/poiseuille.svg"));
  CHECK(!exists(dir + "/poiseuille.png"));
  // One line says so and how to draw them.
  int lines = 0;
  std::istringstream out(r.out);
  std::string line, said;
  while (std::getline(out, line))
    if (line.find("charts not drawn") != std::string::npos) ++lines, said = line;
  CHECK(lines == 1);
  CHECK(said.find("gnuplot is not on PATH") != std::string::npos);
  CHECK(said.find("`gnuplot " + dir + "/poiseuille.gp`") != std::string::npos);
  CHECK(said.find("`benchmarks/plot_accuracy.sh " + dir + "`") != std::string::npos);

  // benchmarks/plot_accuracy.sh draws them from the CSV, which it leaves as it was.
  const std::string csv = readText(dir + "/accuracy.csv");
  const Result p = runShell("SPH2D=" + q(SPH2D_EXE) + " " +
                            q(std::string(SPH2D_SOURCE_DIR) + "/benchmarks/plot_accuracy.sh") + " " + q(dir));
  INFO(p.out);
  CHECK(p.code == 0);
  CHECK(readXml(readText(dir + "/poiseuille.svg")).why.empty());
  CHECK(readText(dir + "/accuracy.csv") == csv);

  // The script drawn by hand, from another folder, finds its data and writes beside itself.
  const std::string hand = freshDir("charts_by_hand");
  std::filesystem::copy(dir + "/poiseuille.gp", hand);
  std::filesystem::copy(dir + "/poiseuille.dat", hand);
  const Result g = runShell("cd / && gnuplot " + q(hand + "/poiseuille.gp"));
  INFO(g.out);
  CHECK(g.code == 0);
  const Xml svg = readXml(readText(hand + "/poiseuille.svg"));
  CHECK(svg.why.empty());
  CHECK(svg.texts.size() > 10);
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgba;
  sph2d::readPng(hand + "/poiseuille.png", w, h, rgba);
  CHECK(w == 960);
}

TEST_CASE(
    "bench accuracy --charts-only: a CSV's names reach gnuplot as text only, unstable runs are named, the CSV stays") {
  requireGnuplot();
  const std::string dir = freshDir("charts_only"), pwned = dir + "/pwned";
  const std::string csv =
      "run_id,case,solver,floor,particles,cfl,error_name,error,error2_name,error2,mean_density_error,"
      "max_density_error,wall_s_per_sim_s,ms_per_step,status,build,settings,solver_params\n"
      "poiseuille-game-80-cfl1,poiseuille,game,,80,6,u_rms_vs_series,0.03,,,0.01,0.001,0.02,1,ok,abc,quick=1,x\n"
      "poiseuille-game-200-cfl1,poiseuille,game,,200,6,u_rms_vs_series,0.02,,,0.01,0.001,0.1,1,ok,abc,quick=1,x\n"
      "poiseuille-evil-80-cfl1,poiseuille,\"`touch " +
      pwned + "`\";system(\"touch " + pwned +
      "\"),,80,1,u_rms_vs_series,0.05,,,0.01,0.001,0.05,1,ok,abc,quick=1,x\n"
      "poiseuille-pbf-200-cfl2,poiseuille,pbf,,200,2,u_rms_vs_series,,,,,,,,unstable,abc,quick=1,x\n";
  {
    std::ofstream f(dir + "/accuracy.csv");
    f << csv;
  }
  // accuracy.csv is not sph2d's here (no journal): --charts-only leaves it alone and is not stopped by it.
  const Result r = run("bench accuracy --charts-only " + q(dir + "/accuracy.csv"));
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(readText(dir + "/accuracy.csv") == csv);
  CHECK(!exists(dir + "/accuracy.md"));
  CHECK(!exists(pwned));
  const std::string gp = readText(dir + "/poiseuille.gp");
  CHECK(gp.find('`') == std::string::npos);
  CHECK(gp.find("system(") == std::string::npos);
  CHECK(gp.find("title \"??touch?") != std::string::npos);  // its name, stripped to plain characters
  const Xml svg = readXml(readText(dir + "/poiseuille.svg"));
  REQUIRE_MESSAGE(svg.why.empty(), svg.why);
  std::set<std::string> texts;
  for (const SvgText& t : svg.texts) texts.insert(t.text);
  CHECK(texts.count("not drawn (unstable):") == 1);  // below the key, a run a line
  CHECK(texts.count("pbf 200 \xc3\x97"
                    "2") == 1);
  CHECK(frontIds(readText(dir + "/poiseuille.dat")) ==
        std::set<std::string>{"poiseuille-game-80-cfl1", "poiseuille-game-200-cfl1"});

  // A chart of that name that sph2d did not write is never overwritten.
  const std::string other = freshDir("charts_only_foreign");
  std::filesystem::copy(dir + "/accuracy.csv", other);
  {
    std::ofstream f(other + "/poiseuille.svg");
    f << "someone's drawing\n";
  }
  const Result refused = run("bench accuracy --charts-only " + q(other + "/accuracy.csv"));
  INFO(refused.out);
  CHECK(refused.code == 2);
  CHECK(refused.out.find("holds poiseuille.svg, which sph2d cannot prove it wrote") != std::string::npos);
  CHECK(readText(other + "/poiseuille.svg") == "someone's drawing\n");
}
