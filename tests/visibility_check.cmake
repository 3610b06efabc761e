# ctest Visibility.SharedLibraryExportsThePublicApiOnly (shared builds): the
# dynamic symbol table of libgravcal.so holds the public API (a function of
# the core, CalibrateFromPositions, is there) and no symbol of gravcal::internal.
# Run as cmake -DLIBRARY=<libgravcal.so> -DNM=<nm> -P visibility_check.cmake
cmake_minimum_required(VERSION 3.16)

foreach(var LIBRARY NM)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "visibility_check.cmake: -D${var}=... is required")
  endif()
endforeach()
execute_process(COMMAND "${NM}" -D -C --defined-only "${LIBRARY}"
  RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "Visibility: ${NM} -D failed on ${LIBRARY}: ${err}")
endif()
string(REPLACE "\n" ";" lines "${out}")
set(public 0)
set(internal "")
foreach(line ${lines})
  # A symbol of gravcal::internal itself (a function, or the typeinfo or
  # vtable of a class); std templates instantiated over internal types (a
  # std::thread running an internal function) are std's, which libstdc++
  # declares with default visibility.
  if(line MATCHES "^[0-9a-f]+ [A-Za-z] (typeinfo for |typeinfo name for |vtable for |VTT for |guard variable for )?gravcal::internal::")
    list(APPEND internal "${line}")
  elseif(line MATCHES "gravcal::")
    math(EXPR public "${public} + 1")
  endif()
endforeach()
list(LENGTH internal internal_count)
if(internal_count GREATER 0)
  list(GET internal 0 first)
  message(FATAL_ERROR "Visibility: ${LIBRARY} exports ${internal_count} symbols of "
                      "gravcal::internal, the first: ${first}")
endif()
if(NOT out MATCHES "gravcal::CalibrateFromPositions\\(")
  message(FATAL_ERROR "Visibility: ${LIBRARY} does not export gravcal::CalibrateFromPositions "
                      "(${public} gravcal symbols exported)")
endif()
message(STATUS "Visibility: ${LIBRARY} exports ${public} gravcal symbols, none internal")
