# Format.ClangFormatClean: every C++ file of the tree is formatted as the
# repository's .clang-format says (clang-format --dry-run --Werror). Fails
# naming the files that are not, and how to fix them.
if(NOT CLANG_FORMAT)
  message(FATAL_ERROR "clang-format not found: apt-get install clang-format")
endif()
file(GLOB_RECURSE files
  ${SOURCE_DIR}/include/*.h ${SOURCE_DIR}/src/*.h ${SOURCE_DIR}/src/*.cc
  ${SOURCE_DIR}/tests/*.h ${SOURCE_DIR}/tests/*.cc
  ${SOURCE_DIR}/benchmarks/*.h ${SOURCE_DIR}/benchmarks/*.cc
  ${SOURCE_DIR}/python/*.cc ${SOURCE_DIR}/fuzz/*.h ${SOURCE_DIR}/fuzz/*.cc)
# One clang-format process for the whole tree (one per file took 35-47 s,
# nearly all of it process start-up). With --dry-run it names each file
# that differs as "<file>:<line>:<col>: error: code should be
# clang-formatted"; the files are taken from those lines.
execute_process(COMMAND ${CLANG_FORMAT} --style=file --dry-run --Werror ${files}
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE messages)
set(bad "")
if(NOT rc EQUAL 0)
  string(REGEX MATCHALL "[^\n]*:[0-9]+:[0-9]+: (error|warning): code should be clang-formatted"
    lines "${messages}")
  foreach(line ${lines})
    string(REGEX REPLACE ":[0-9]+:[0-9]+: (error|warning): .*" "" f "${line}")
    file(RELATIVE_PATH rel ${SOURCE_DIR} ${f})
    list(APPEND bad ${rel})
  endforeach()
  list(REMOVE_DUPLICATES bad)
  if(NOT bad)
    message(FATAL_ERROR "clang-format failed (exit ${rc}):\n${messages}")
  endif()
endif()
if(bad)
  string(REPLACE ";" "\n  " shown "${bad}")
  message(FATAL_ERROR "not clang-formatted (run clang-format -i on them):\n  ${shown}")
endif()
list(LENGTH files n)
message(STATUS "${n} files clang-format clean")
