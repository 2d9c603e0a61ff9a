# cmake -DEXPECT=REGEX -P ExpectOutput.cmake -- COMMAND [ARG...]
#
# Runs COMMAND and passes only if it exits 0 and its standard output matches REGEX. For tests that
# check what a program prints: ctest's PASS_REGULAR_EXPRESSION alone ignores the exit code, so a
# program that printed the right lines and then crashed (a sanitizer report at exit) would pass.
cmake_minimum_required(VERSION 3.22)

if(NOT DEFINED EXPECT)
  message(FATAL_ERROR "ExpectOutput.cmake: -DEXPECT=REGEX is required")
endif()
set(command "")
set(seen_separator FALSE)
math(EXPR last "${CMAKE_ARGC} - 1")
foreach(i RANGE ${last})
  if(seen_separator)
    string(REPLACE ";" "\\;" argument "${CMAKE_ARGV${i}}")  # one argument, not a list
    list(APPEND command "${argument}")
  elseif(CMAKE_ARGV${i} STREQUAL "--")
    set(seen_separator TRUE)
  endif()
endforeach()
if(NOT command)
  message(FATAL_ERROR "ExpectOutput.cmake: no command after --")
endif()

execute_process(COMMAND ${command} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "exited with ${rc}: ${command}")
endif()
if(NOT out MATCHES "${EXPECT}")
  message(FATAL_ERROR "the output does not match:\n${EXPECT}")
endif()
