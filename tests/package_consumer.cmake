# Package.Consumer (tests/CMakeLists.txt): installs the build tree's library, headers and CMake
# package into a fresh prefix, then configures, builds and runs examples/consumer out of tree
# against that prefix alone, on the bundled bunny. cmake -P with -DBUILD_DIR -DSOURCE_DIR
# -DWORK_DIR -DCXX_COMPILER -DGPL (ON/OFF, the build's REMORA_WITH_GPL_SOLVERS) and optionally
# -DLAUNCHER (a compiler launcher such as ccache).
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR CXX_COMPILER GPL)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "package_consumer.cmake: -D${var}=... is missing")
  endif()
endforeach()

function(run_step name)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name} failed (${rc}):\n${out}\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run_step(install ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

set(launcher)
if(LAUNCHER)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
# Only the prefix: no package registry, no source or build tree of Remora.
run_step(configure ${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/consumer -B ${WORK_DIR}/build
         -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX_COMPILER} ${launcher}
         -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
if(GPL)
  set(expected "GPL solvers: ON")
else()
  set(expected "GPL solvers: OFF")
endif()
string(FIND "${step_output}" "${expected}" found)
if(found EQUAL -1)
  message(FATAL_ERROR "the package does not say '${expected}':\n${step_output}")
endif()
file(STRINGS ${WORK_DIR}/build/CMakeCache.txt remora_dir REGEX "^remora_DIR:")
if(NOT remora_dir MATCHES "^remora_DIR:PATH=${prefix}/")
  message(FATAL_ERROR "the consumer found Remora elsewhere than in ${prefix}: ${remora_dir}")
endif()

run_step(build ${CMAKE_COMMAND} --build ${WORK_DIR}/build)

# Every installed header compiles on its own terms: one translation unit includes them all.
file(GLOB_RECURSE headers RELATIVE ${prefix}/include ${prefix}/include/remora/*.h)
set(includes "")
foreach(header ${headers})
  string(APPEND includes "#include <${header}>\n")
endforeach()
file(WRITE ${WORK_DIR}/headers/all_headers.cpp "${includes}")
file(WRITE ${WORK_DIR}/headers/CMakeLists.txt "cmake_minimum_required(VERSION 3.16)
project(headers LANGUAGES CXX)
find_package(remora CONFIG REQUIRED)
add_library(all_headers OBJECT all_headers.cpp)
target_link_libraries(all_headers PRIVATE remora::remora)
")
run_step(configure-headers ${CMAKE_COMMAND} -S ${WORK_DIR}/headers -B ${WORK_DIR}/headers/build
         -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX_COMPILER} ${launcher}
         -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run_step(build-headers ${CMAKE_COMMAND} --build ${WORK_DIR}/headers/build)
run_step(run ${WORK_DIR}/build/lift ${SOURCE_DIR}/data/bunny.ply ${WORK_DIR}/lifted.ply)
message(STATUS "${step_output}")
if(NOT EXISTS ${WORK_DIR}/lifted.ply)
  message(FATAL_ERROR "lift wrote no ${WORK_DIR}/lifted.ply")
endif()
