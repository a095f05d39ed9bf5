# CTest's install/find_package test: install the build into a fresh prefix,
# configure and build tests/install/consumer against it (find_package(sph2d)),
# run the program. Arguments: BUILD_DIR, WORK, CONSUMER, CXX, GENERATOR.
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
if(NOT STEP_OUT MATCHES "consumer: [0-9]+ particles, state [0-9a-f]+, water")
  message(FATAL_ERROR "unexpected output")
endif()
if(NOT EXISTS "${WORK}/frame.png")
  message(FATAL_ERROR "no frame written")
endif()
