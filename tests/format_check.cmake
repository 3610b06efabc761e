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
set(bad "")
foreach(f ${files})
  execute_process(COMMAND ${CLANG_FORMAT} --style=file --dry-run --Werror ${f}
    RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
  if(NOT rc EQUAL 0)
    file(RELATIVE_PATH rel ${SOURCE_DIR} ${f})
    list(APPEND bad ${rel})
  endif()
endforeach()
if(bad)
  string(REPLACE ";" "\n  " shown "${bad}")
  message(FATAL_ERROR "not clang-formatted (run clang-format -i on them):\n  ${shown}")
endif()
list(LENGTH files n)
message(STATUS "${n} files clang-format clean")
