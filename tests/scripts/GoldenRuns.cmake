# Included by the cmake -P scripts that run `tickfx` binaries other than the build under test
# against the golden state hashes: BuildVariants.cmake (other compilers and flags) and
# GoldenHashes.cmake (one binary, possibly under an emulator: scripts/test's aarch64 stage).
#
# Both check the same list the same way: every sample of GOLDEN_FILE and every golden effect of
# GOLDEN_EFFECTS_FILE, run from SOURCE_DIR. Those three variables are the including script's.

# Sets `golden_effects` (paths relative to SOURCE_DIR) and, for each, `golden_<effect>` (its
# hash) in the caller's scope. Each list names effects in its own folder: the samples', and the
# golden effects' beside their list.
function(golden_read_lists)
  get_filename_component(effects_dir ${GOLDEN_EFFECTS_FILE} DIRECTORY)
  file(RELATIVE_PATH effects_folder ${SOURCE_DIR} ${effects_dir})
  set(effects "")
  foreach(list_and_folder "${GOLDEN_FILE}|samples" "${GOLDEN_EFFECTS_FILE}|${effects_folder}")
    string(REPLACE "|" ";" list_and_folder "${list_and_folder}")
    list(GET list_and_folder 0 list_file)
    list(GET list_and_folder 1 folder)
    file(STRINGS ${list_file} lines)
    set(listed 0)
    foreach(line ${lines})
      if(line MATCHES "^([^# \t]+)[ \t]+([0-9a-f]+)[ \t]*$")
        list(APPEND effects ${folder}/${CMAKE_MATCH_1})
        set(golden_${folder}/${CMAKE_MATCH_1} ${CMAKE_MATCH_2} PARENT_SCOPE)
        math(EXPR listed "${listed} + 1")
      endif()
    endforeach()
    if(listed EQUAL 0)
      message(FATAL_ERROR "no hashes in ${list_file}")
    endif()
  endforeach()
  set(golden_effects ${effects} PARENT_SCOPE)
endfunction()

# Left-aligns `text` in `width` columns, appended to the variable `out`.
function(append_cell out text width)
  string(LENGTH "${text}" n)
  set(spaces "")
  if(n LESS width)
    math(EXPR pad "${width} - ${n}")
    string(REPEAT " " ${pad} spaces)
  endif()
  set(${out} "${${out}}${text}${spaces}  " PARENT_SCOPE)
endfunction()

# The hash `tickfx` gives for `effect` (a path relative to SOURCE_DIR), or a word saying why there
# is none. Arguments after `effect` are the launcher the binary runs under (an emulator), if any.
# 60 fps frames take the driver's path, as a user's run does, where the golden test takes
# stepTicks. The run must have run exactly 2 s of ticks (`run` never drops one): any other count is
# a failure of its own.
function(hash_of out tickfx effect)
  if(NOT tickfx)
    set(${out} "no-build" PARENT_SCOPE)
    return()
  endif()
  execute_process(
    COMMAND ${ARGN} ${tickfx} run ${effect} --seconds 2 --fps 60 --format none --hash
    WORKING_DIRECTORY ${SOURCE_DIR}
    RESULT_VARIABLE rc OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
  set(hash "")
  if(stdout MATCHES "state-hash: ([0-9a-f]+)")
    set(hash ${CMAKE_MATCH_1})
  endif()
  if(NOT rc EQUAL 0 OR NOT hash)
    message("${ARGN} ${tickfx} run ${effect} failed (${rc}):\n${stdout}\n${stderr}")
    set(${out} "run-failed" PARENT_SCOPE)
  elseif(NOT stdout MATCHES "\\(([0-9]+) ticks at ([0-9]+) Hz")
    message("${tickfx} run ${effect}: no tick count in the summary:\n${stdout}")
    set(${out} "no-tick-count" PARENT_SCOPE)
  else()
    set(ran ${CMAKE_MATCH_1})
    math(EXPR twoSeconds "2 * ${CMAKE_MATCH_2}")
    if(NOT ran EQUAL twoSeconds)
      message("${tickfx} run ${effect}: ran ${ran} ticks, not 2 s:\n${stdout}")
      set(${out} "wrong-ticks" PARENT_SCOPE)
    else()
      set(${out} ${hash} PARENT_SCOPE)
    endif()
  endif()
endfunction()

# golden_check(<failures-var> run...): runs every golden effect through each run's binary,
# `${run}_tickfx` (empty when it did not build), under `${run}_launcher` if that is set; prints one
# table of hashes and adds the runs that missed their golden hash to <failures-var>.
function(golden_check failures_var)
  golden_read_lists()
  set(failures ${${failures_var}})
  set(table "")
  append_cell(table "effect" 52)
  append_cell(table "golden" 16)
  foreach(r ${ARGN})
    append_cell(table "${r}" 17)
  endforeach()
  string(APPEND table "\n")
  foreach(e ${golden_effects})
    append_cell(table "${e}" 52)
    append_cell(table "${golden_${e}}" 16)
    foreach(r ${ARGN})
      hash_of(cell "${${r}_tickfx}" ${e} ${${r}_launcher})
      if(NOT cell STREQUAL "${golden_${e}}")
        string(APPEND cell "*")
        math(EXPR failures "${failures} + 1")
      endif()
      append_cell(table "${cell}" 17)
    endforeach()
    string(APPEND table "\n")
  endforeach()
  message("state hashes of `tickfx run <effect> --seconds 2 --fps 60 --format none --hash` "
          "(* not the golden hash):\n${table}")
  set(${failures_var} ${failures} PARENT_SCOPE)
endfunction()
