# CTest's install/find_package test: install the build into a fresh prefix,
# configure and build tests/install/consumer against it (find_package(sph2d)),
# run the program (a game: a floating crate, a paddle, team colours, a save and a
# reload, frames drawn into its own OpenGL context). Arguments: BUILD_DIR, WORK, CONSUMER, CXX, GENERATOR.
file(REMOVE_RECURSE "${WORK}")
function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(STEP_OUT "${out}" PARENT_SCOPE)
endfunction()

step("install" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK}/prefix")
foreach(f include/sph2d/world.hpp include/sph2d/render/renderer.hpp lib/cmake/sph2d/sph2dConfig.cmake)
  if(NOT EXISTS "${WORK}/prefix/${f}")
    message(FATAL_ERROR "the install lacks ${f}")
  endif()
endforeach()
# The installed headers are the public API alone: none includes Eigen or shows the solver's
# working fields or the job system.
file(GLOB_RECURSE installed_headers "${WORK}/prefix/include/sph2d/*.hpp")
foreach(h IN LISTS installed_headers)
  file(READ "${h}" text)
  foreach(internal "#include <Eigen" "xPrev" "invRho" "pOverRho" "ThreadPool" "thread_pool.hpp" "kernels.hpp")
    string(FIND "${text}" "${internal}" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "the installed ${h} shows the engine's internals (${internal})")
    endif()
  endforeach()
endforeach()
step("configure" ${CMAKE_COMMAND} -S "${CONSUMER}" -B "${WORK}/build" -G "${GENERATOR}"
     -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${WORK}/prefix
     -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
string(FIND "${STEP_OUT}" "sph2d found in ${WORK}/prefix/lib/cmake/sph2d" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the consumer did not find the installed package:\n${STEP_OUT}")
endif()
step("build" ${CMAKE_COMMAND} --build "${WORK}/build")
step("run" "${WORK}/build/consumer" "${WORK}/frame.png")
message("${STEP_OUT}")
# The consumer exits 1 when a check fails; its lines say what it saw.
foreach(line "consumer: [0-9]+ particles, state [0-9a-f]+, water"
             "crate at y = [0-9.]+ m after [0-9]+ frames: afloat"
             "reloaded: state equal to the uninterrupted World's"
             "drawn into the game's own context .*game state kept")
  if(NOT STEP_OUT MATCHES "${line}")
    message(FATAL_ERROR "unexpected output: no line matching '${line}'")
  endif()
endforeach()
if(NOT EXISTS "${WORK}/frame.png")
  message(FATAL_ERROR "no frame written")
endif()

# The engine alone, on a view of the machine without Eigen, OSMesa and libpng (pkg-config
# sees no modules, find_package(PNG) and find_package(Eigen3) are disabled, and Eigen's
# headers are not on the default include path): it configures, builds and runs, so the
# public headers need no Eigen; and its own source is compiled without our floating-point
# flags unless it opts in.
set(ENGINE_ONLY "${CONSUMER}/../engine_only")
set(NO_RENDER_DEPS ${CMAKE_COMMAND} -E env PKG_CONFIG_LIBDIR=${WORK}/no-pkgconfig PKG_CONFIG_PATH=)
set(NO_RENDER_ARGS -DCMAKE_DISABLE_FIND_PACKAGE_PNG=ON -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON -DCMAKE_PREFIX_PATH=${WORK}/prefix
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_CXX_COMPILER=${CXX} -G "${GENERATOR}")
step("configure engine_only" ${NO_RENDER_DEPS} ${CMAKE_COMMAND} -S "${ENGINE_ONLY}" -B "${WORK}/engine_only"
     -DCMAKE_BUILD_TYPE=Release -DCMAKE_EXPORT_COMPILE_COMMANDS=ON ${NO_RENDER_ARGS})
file(READ "${WORK}/engine_only/compile_commands.json" commands)
if(commands MATCHES "ffp-contract")
  message(FATAL_ERROR "sph2d::engine imposed its floating-point flags on the game's source:\n${commands}")
endif()
if(commands MATCHES "eigen3")
  message(FATAL_ERROR "sph2d::engine put Eigen on the game's include path:\n${commands}")
endif()
step("build engine_only" ${CMAKE_COMMAND} --build "${WORK}/engine_only")
step("run engine_only" "${WORK}/engine_only/engine_only")
message("${STEP_OUT}")
step("configure engine_only, deterministic" ${NO_RENDER_DEPS} ${CMAKE_COMMAND} -S "${ENGINE_ONLY}"
     -B "${WORK}/engine_only_det" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON -DSPH2D_CONSUMER_DETERMINISTIC=ON ${NO_RENDER_ARGS})
file(READ "${WORK}/engine_only_det/compile_commands.json" commands)
if(NOT commands MATCHES "-ffp-contract=off" OR NOT commands MATCHES "-fno-fast-math")
  message(FATAL_ERROR "sph2d::deterministic did not add the floating-point flags:\n${commands}")
endif()
# The renderer asked for on that view: refused, naming what is missing.
execute_process(COMMAND ${NO_RENDER_DEPS} ${CMAKE_COMMAND} -S "${CONSUMER}" -B "${WORK}/consumer_no_deps" ${NO_RENDER_ARGS}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX REPLACE "[ \n]+" " " err "${err}")  # CMake wraps the package's message
if(rc EQUAL 0 OR NOT err MATCHES "render needs OSMesa \\(pkg-config module osmesa; Debian: libosmesa6-dev"
   OR NOT err MATCHES "render needs libpng \\(Debian: libpng-dev\\)")
  message(FATAL_ERROR "find_package(sph2d) with render on a machine without OSMesa and libpng: exit ${rc}\n${out}\n${err}")
endif()
message("install test: engine alone without OSMesa/libpng: OK; render refused naming them")
