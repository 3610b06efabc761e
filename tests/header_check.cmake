# ctest HeaderCheck.*: compiles a translation unit that includes one public
# header (-fsyntax-only) with only the include directories given, and lists
# the headers it pulls in (-H). Fails when the compile fails, or when
# FORBIDDEN (a regex over the included paths, e.g. "/(ceres|glog)/") matches
# with EXPECT=absent, or matches nothing with EXPECT=present (the check of
# the check: gravcal/ceres.h must be seen to include Ceres). With
# -DPREPROCESS_ONLY=ON the unit is only preprocessed (-E), which lists the
# same includes in a fraction of the time. A system-wide
# Ceres in /usr/include cannot be taken off the compiler's default path,
# so the list of included files, not the flags, is what shows that the core
# needs no Ceres. Run as
#   cmake -DCXX=<c++> -DHEADER=gravcal/gravcal.h -DINCLUDE_DIRS=<a|b|...>
#         -DFORBIDDEN=<regex> -DEXPECT=absent|present -DWORK_DIR=<dir> -P header_check.cmake
cmake_minimum_required(VERSION 3.16)

foreach(var CXX HEADER INCLUDE_DIRS FORBIDDEN EXPECT WORK_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "header_check.cmake: -D${var}=... is required")
  endif()
endforeach()

string(MAKE_C_IDENTIFIER "${HEADER}" stem)
set(source "${WORK_DIR}/header_check_${stem}.cc")
file(MAKE_DIRECTORY "${WORK_DIR}")
file(WRITE "${source}" "#include \"${HEADER}\"\nint main() { return 0; }\n")

if(PREPROCESS_ONLY)
  set(args -std=c++17 -E -o /dev/null -H)
else()
  set(args -std=c++17 -fsyntax-only -H)
endif()
string(REPLACE "|" ";" include_dirs "${INCLUDE_DIRS}")
foreach(dir ${include_dirs})
  list(APPEND args "-I${dir}")
endforeach()
execute_process(COMMAND "${CXX}" ${args} "${source}"
  RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT result EQUAL 0)
  string(JOIN " " command_line "${CXX}" ${args} "${source}")
  message(FATAL_ERROR "HeaderCheck: ${HEADER} does not compile with only ${INCLUDE_DIRS}\n"
                      "command: ${command_line}\n${err}")
endif()

# -H writes one line per included file: dots (the depth), a space, the path.
string(REPLACE "\n" ";" lines "${err}")
set(included 0)
set(matches "")
foreach(line ${lines})
  if(line MATCHES "^\\.+ (.*)$")
    math(EXPR included "${included} + 1")
    set(path "${CMAKE_MATCH_1}")
    if(path MATCHES "${FORBIDDEN}")
      list(APPEND matches "${path}")
    endif()
  endif()
endforeach()
list(LENGTH matches count)
if(included EQUAL 0)
  message(FATAL_ERROR "HeaderCheck: the compiler listed no included file for ${HEADER} (no -H?)")
endif()
if(EXPECT STREQUAL "absent" AND count GREATER 0)
  list(GET matches 0 first)
  message(FATAL_ERROR "HeaderCheck: ${HEADER} includes ${count} headers matching "
                      "'${FORBIDDEN}', the first ${first}")
elseif(EXPECT STREQUAL "present" AND count EQUAL 0)
  message(FATAL_ERROR "HeaderCheck: ${HEADER} includes nothing matching '${FORBIDDEN}' "
                      "(expected it to; is the check still seeing the includes?)")
endif()
message(STATUS "HeaderCheck: ${HEADER}: ${included} files included, ${count} matching "
               "'${FORBIDDEN}' (expected ${EXPECT})")
file(REMOVE "${source}")
