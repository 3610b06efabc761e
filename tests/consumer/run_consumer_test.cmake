# ctest ConsumerProject.InstallsAndLinks: installs the built gravcal tree into
# a temporary prefix, then configures, builds and runs tests/consumer against
# it. Run as
#   cmake -DGRAVCAL_BUILD_DIR=<build> -DCONSUMER_SOURCE_DIR=<tests/consumer>
#         [-DCONSUMER_GENERATOR=<gen>] [-DCONSUMER_CXX_COMPILER=<c++>]
#         [-DCONSUMER_CXX_FLAGS=<flags>] [-DCONSUMER_PREFIX_PATH=<a|b|...>]
#         [-DCONSUMER_PACKAGE_DIRS=<Var=dir|...>] -P run_consumer_test.cmake
# Lists are '|'-separated (a ';' would be split by add_test). Each run works in
# its own directory under <build>/consumer_test, removed when the run passes.
cmake_minimum_required(VERSION 3.16)

foreach(var GRAVCAL_BUILD_DIR CONSUMER_SOURCE_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "run_consumer_test.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT EXISTS "${GRAVCAL_BUILD_DIR}/cmake_install.cmake")
  message(FATAL_ERROR "ConsumerProject: ${GRAVCAL_BUILD_DIR} is not a configured gravcal build "
                      "tree (no cmake_install.cmake); build it before running ctest")
endif()

string(RANDOM LENGTH 8 ALPHABET "0123456789abcdef" run_id)
set(work_dir "${GRAVCAL_BUILD_DIR}/consumer_test/run-${run_id}")
set(prefix "${work_dir}/prefix")
set(consumer_build "${work_dir}/build")
file(REMOVE_RECURSE "${work_dir}")
file(MAKE_DIRECTORY "${work_dir}")

# Runs one step; stops the test with the step's name and output on failure.
function(run_step name)
  execute_process(COMMAND ${ARGN}
    RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result EQUAL 0)
    string(JOIN " " command_line ${ARGN})
    message(FATAL_ERROR "ConsumerProject: ${name} FAILED (exit ${result}); work dir kept: "
                        "${work_dir}\ncommand: ${command_line}\n"
                        "--- stdout ---\n${out}\n--- stderr ---\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

# 1. Install the already-built tree. A missing library or tool (tree not
# built) fails here.
run_step("install of ${GRAVCAL_BUILD_DIR} into ${prefix}"
  "${CMAKE_COMMAND}" --install "${GRAVCAL_BUILD_DIR}" --prefix "${prefix}")
file(GLOB_RECURSE config_files "${prefix}/*/gravcalConfig.cmake")
if(NOT config_files)
  message(FATAL_ERROR "ConsumerProject: install put no gravcalConfig.cmake under ${prefix}")
endif()

# 2. Configure the consumer against the prefix only (plus where the parent
# build found its dependencies).
set(prefix_path "${prefix}")
if(CONSUMER_PREFIX_PATH)
  string(REPLACE "|" ";" extra "${CONSUMER_PREFIX_PATH}")
  list(APPEND prefix_path ${extra})
endif()
string(REPLACE ";" "\\;" prefix_path_arg "${prefix_path}")
set(configure_args
  -S "${CONSUMER_SOURCE_DIR}" -B "${consumer_build}"
  -DCMAKE_BUILD_TYPE=Release
  "-DCMAKE_PREFIX_PATH=${prefix_path_arg}"
  # Only the temporary prefix may provide gravcal.
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
if(CONSUMER_GENERATOR)
  list(APPEND configure_args -G "${CONSUMER_GENERATOR}")
endif()
if(CONSUMER_CXX_COMPILER)
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER=${CONSUMER_CXX_COMPILER}")
endif()
if(CONSUMER_CXX_FLAGS)
  list(APPEND configure_args "-DCMAKE_CXX_FLAGS=${CONSUMER_CXX_FLAGS}"
    "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_CXX_FLAGS}")
endif()
if(CONSUMER_PACKAGE_DIRS)
  string(REPLACE "|" ";" package_dirs "${CONSUMER_PACKAGE_DIRS}")
  foreach(entry ${package_dirs})
    list(APPEND configure_args "-D${entry}")
  endforeach()
endif()
run_step("configure of the consumer project" "${CMAKE_COMMAND}" ${configure_args})

# 3. Build it. 4. Run its programs: the core alone, then through gravcal::ceres.
run_step("build of the consumer project" "${CMAKE_COMMAND}" --build "${consumer_build}")
foreach(consumer core_consumer ceres_consumer)
  set(consumer_exe "${consumer_build}/${consumer}")
  if(NOT EXISTS "${consumer_exe}")
    message(FATAL_ERROR "ConsumerProject: build produced no ${consumer_exe}")
  endif()
  run_step("run of ${consumer}" "${consumer_exe}")
  message(STATUS "${step_output}")
endforeach()

file(REMOVE_RECURSE "${work_dir}")
