// app/commands.hpp — the sph2d commands: main.cpp dispatches to them, each lives in
// its own cmd_*.cpp. Each takes the arguments after its name and returns the exit
// code (0 ok, 1 runtime failure, 2 bad input, 3 guard, 130 interrupted); bad input
// may also be thrown (UsageError, SceneError) for main to report.
#pragma once

#include <string>
#include <vector>

namespace sph2d::cli {

/// `sph2d run` (cmd_run.cpp).
int cmdRun(const std::vector<std::string>& args);
/// `sph2d serve` (cmd_serve.cpp).
int cmdServe(const std::vector<std::string>& args);
/// `sph2d bench serve` (cmd_bench_serve.cpp).
int cmdBenchServe(const std::vector<std::string>& args);
/// `sph2d check` (cmd_check.cpp).
int cmdCheck(const std::vector<std::string>& args);
/// `sph2d render` (cmd_render.cpp).
int cmdRender(const std::vector<std::string>& args);
/// `sph2d bench` and `sph2d bench render` (cmd_bench.cpp).
int cmdBench(const std::vector<std::string>& args);
/// `sph2d info` (cmd_info.cpp).
int cmdInfo(const std::vector<std::string>& args);
/// `sph2d bench step` (cmd_bench_step.cpp).
int cmdBenchStep(const std::vector<std::string>& args);
/// `sph2d bench accuracy` (cmd_bench_accuracy.cpp).
int cmdBenchAccuracy(const std::vector<std::string>& args);
/// `sph2d bench game` (cmd_bench_game.cpp).
int cmdBenchGame(const std::vector<std::string>& args);
/// `sph2d bench effects` (cmd_bench_effects.cpp).
int cmdBenchEffects(const std::vector<std::string>& args);

}  // namespace sph2d::cli
