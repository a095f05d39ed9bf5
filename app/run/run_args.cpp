// app/run/run_args.cpp — parsing and help of `sph2d run`'s command line; see run_args.hpp.
#include "run/run_args.hpp"

#include <algorithm>
#include <cstdio>

#include "cli.hpp"

namespace sph2d::cli {
namespace {

const char* kRunHelp =
    "Usage: sph2d run SCENE.json [options]\n"
    "\n"
    "Simulates SCENE and writes frame_00000.png, frame_00001.png, ... (frame k shows\n"
    "the state after k frames of 1/fps seconds) and manifest.json (per-frame hashes of\n"
    "the pixels and of the state, and the events applied, for `sph2d check`).\n"
    "The loop has a fixed time step: the simulation always advances whole frames of\n"
    "1/fps (the scene's rate). By default it runs as fast as it can and renders every\n"
    "kept frame; with --realtime it keeps pace with the wall clock and, when it cannot,\n"
    "renders fewer frames (dropped) or, beyond --catch-up frames per render, lets the\n"
    "simulation fall behind (late); the summary reports both.\n"
    "\n"
    "Options:\n"
    "  --out DIR       output directory (default: out/<scene name>). A run never removes\n"
    "                  or overwrites a file it did not write: it removes only the frames,\n"
    "                  exports and manifest an earlier sph2d run wrote there (its manifest\n"
    "                  or DIR/.sph2d.journal lists them with their hashes) and says so; a\n"
    "                  frame_*, bodies_* or manifest.json file there that sph2d cannot prove\n"
    "                  it wrote, or a symbolic link of such a name, is refused (exit 2, naming\n"
    "                  it). Other files are left alone\n"
    "  --frames N      number of frames (default: the scene's duration × fps)\n"
    "  --every K       keep every K-th frame (0, K, 2K, ...; default 1)\n"
    "  --threads T     simulation threads (default: all cores; one fewer when the run\n"
    "                  draws frames without --realtime or --input -: the loop then steps\n"
    "                  ahead of the drawing, whose thread holds a core)\n"
    "  --realtime      pace the loop to the wall clock (one simulated second per second)\n"
    "  --catch-up N    with --realtime: at most N frames stepped per render (default 4)\n"
    "  --input FILE    apply the events of FILE: one JSON object per line, each with\n"
    "                  \"frame\" or \"t\" (docs/SCENES.md); may be repeated\n"
    "  --input -       apply events read from standard input, one JSON object per line,\n"
    "                  at the next frame; a bad line is reported and skipped. Standard input\n"
    "                  is input from elsewhere: its block and drop events are held to the caps\n"
    "                  of `sph2d serve`'s network (a line over one is skipped with a warning):\n"
    "  --max-event-particles N      the most particles one --input - event may add (default\n"
    "                  a quarter of S, the scene's own count: max(1024, its blocks, emitters\n"
    "                  and timeline))\n"
    "  --max-particles-per-second N the most --input - events may add in any second of wall\n"
    "                  time (default S/2)\n"
    "  --max-particles N            no --input - event takes the fluid past N particles\n"
    "                  (default 4 x S, at most the scene's own budget); events files and the\n"
    "                  scene's timeline are the scene author's: only the scene's budget holds them\n"
    "  --record FILE   write every applied event with its frame (replay it with --input);\n"
    "                  an existing FILE is replaced only when it is in DIR and an earlier\n"
    "                  run's manifest lists it (else exit 2)\n"
    "  --max-memory S  refuse (exit 2) a scene whose estimated peak memory exceeds S (512M,\n"
    "                  2G, ...; default: the memory available)\n"
    "  --png-level N   PNG compression 0..9 (default 1: fast)\n"
    "  --export FMT    also write each kept frame's particles: csv, vtk (binary) or vtk-ascii;\n"
    "                  or surface: the fluid's outlines as frame_NNNNN.json and frame_NNNNN.svg\n"
    "  --video FILE    also encode the kept frames into FILE with ffmpeg (must be installed);\n"
    "                  an existing FILE is replaced under --record's rule\n"
    "%s"
    "  --no-images     simulate only; write no PNG and no manifest\n"
    "  --state-hash    print 'state-hash: <16 hex digits>' (XXH64 of ids, positions,\n"
    "                  velocities) as the last line\n"
    "  --profile       print each stage's time and call count\n"
    "  --quiet         no progress and no event lines\n"
    "  --help          this text\n"
    "\n"
    "Exit codes: 0 ok; 1 runtime failure; 2 bad input (command line, scene, an unreadable\n"
    "--input file, an unwritable --record file, an output file sph2d did not write in the\n"
    "way); 3 the simulation guard stopped the run;\n"
    "130 interrupted (SIGINT/SIGTERM: the step under way stops within milliseconds, the\n"
    "frames written stay whole, and the process ends within a second). A malformed event\n"
    "line is a warning, not an error.\n";

}  // namespace

bool wantsRunHelp(const std::vector<std::string>& args) {
  return std::any_of(args.begin(), args.end(), [](const std::string& s) { return s == "--help" || s == "-h"; });
}

void printRunHelp() { std::printf(kRunHelp, kRenderFlagsHelp); }

RunArgs parseRunArgs(const std::vector<std::string>& a) {
  RunArgs r;
  for (ArgReader opt(a, "run"); opt.next();) {
    const std::string s = opt.arg();
    if (parseRenderFlag(opt, r.render)) continue;
    if (opt.is("--out"))
      r.out = opt.value();
    else if (opt.is("--frames"))
      r.frames = opt.intValue(1, 10000000);
    else if (opt.is("--every"))
      r.every = opt.intValue(1, 10000000);
    else if (opt.is("--threads"))
      r.threads = opt.intValue(1, 256);
    else if (opt.is("--png-level"))
      r.pngLevel = opt.intValue(0, 9);
    else if (opt.is("--video"))
      r.video = opt.value();
    else if (opt.is("--export")) {
      ExportFormat f;
      const std::string v = opt.value();
      if (!parseExportFormat(v, f))
        throw UsageError("--export expects csv, vtk, vtk-ascii or surface, got '" + v + "'");
      r.exportFormat = f;
    } else if (opt.is("--realtime"))
      r.realtime = true;
    else if (opt.is("--catch-up"))
      r.catchUp = opt.intValue(1, 1000);
    else if (opt.is("--input")) {
      r.inputs.push_back(opt.value());
      if (r.inputs.back() == "-" && std::count(r.inputs.begin(), r.inputs.end(), "-") > 1)
        throw UsageError("--input - may be given once (there is one standard input)");
    } else if (opt.is("--record"))
      r.record = opt.value();
    else if (opt.is("--max-memory"))
      r.maxMemory = opt.bytesValue();
    else if (opt.is("--max-event-particles"))
      r.maxEventParticles = std::size_t(opt.intValue(1, 100000000));
    else if (opt.is("--max-particles-per-second"))
      r.maxParticlesPerSecond = std::size_t(opt.intValue(1, 100000000));
    else if (opt.is("--max-particles"))
      r.maxParticles = std::size_t(opt.intValue(1, 100000000));
    else if (opt.is("--no-images"))
      r.images = false;
    else if (opt.is("--state-hash"))
      r.stateHash = true;
    else if (opt.is("--profile"))
      r.profile = true;
    else if (opt.is("--quiet"))
      r.quiet = true;
    else if (opt.option())
      opt.unknown();
    else if (r.scene.empty())
      r.scene = s;
    else
      throw UsageError("unexpected argument '" + s + "' (one scene per run)");
  }
  if (r.scene.empty()) throw UsageError("missing the scene file (see sph2d run --help)");
  if (!r.images && (r.exportFormat || !r.video.empty()))
    throw UsageError("--no-images cannot be combined with --export or --video");
  return r;
}

}  // namespace sph2d::cli
