# libFuzzer targets guarding every reader of untrusted input (tests/fuzz/), built with
# -DTICKFX_FUZZ=ON in the clang sanitizer build. Each runs under ctest as fuzz.<reader> for a fixed
# number of executions from a fixed seed, starting from its committed seed corpus (and the samples
# and test effects for the effect loader): a crash, a leak, a sanitizer report or an input slower
# than 10 s fails it, and libFuzzer leaves the input in build/.../fuzz/<reader>/ to reproduce it.
# scripts/fuzz runs the same targets for as long as asked (the longer campaigns).
if(NOT TICKFX_FUZZ)
  return()
endif()

set(fuzz_dir ${CMAKE_CURRENT_SOURCE_DIR}/fuzz)
# Per reader: its source, its executions under ctest (about 20 s each here, ASan and UBSan
# included), which reader the shared source builds, and seed folders besides its own corpus.
set(tickfx_fuzzers effect checkpoint csv ply vdb_points frame_times)
set(effect_source fuzz_effect.cpp)
set(effect_runs 6000)
set(effect_seeds ${PROJECT_SOURCE_DIR}/samples ${CMAKE_CURRENT_SOURCE_DIR}/data/golden)
set(checkpoint_source fuzz_checkpoint.cpp)
set(checkpoint_runs 20000)
set(frame_times_source fuzz_frame_times.cpp)
set(frame_times_runs 60000)
foreach(reader csv ply vdb_points)
  set(${reader}_source fuzz_point_caches.cpp)
endforeach()
set(csv_reader 1)
set(csv_runs 40000)
set(ply_reader 2)
set(ply_runs 40000)
set(vdb_points_reader 3)
set(vdb_points_runs 8000)

foreach(reader ${tickfx_fuzzers})
  set(target fuzz_${reader})
  add_executable(${target} ${fuzz_dir}/${${reader}_source})
  # tickfx_app for the frame-time reader (app/FrameTimes), the rest are io's readers.
  target_link_libraries(${target} PRIVATE tickfx::io tickfx_app)
  target_link_options(${target} PRIVATE -fsanitize=fuzzer)
  if(DEFINED ${reader}_reader)
    target_compile_definitions(${target} PRIVATE TICKFX_FUZZ_READER=${${reader}_reader})
  endif()
  set_target_properties(${target} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/fuzz)

  # The first directory is libFuzzer's working corpus (it adds what it finds there), the others
  # are read only.
  set(work ${PROJECT_BINARY_DIR}/fuzz/${reader})
  file(MAKE_DIRECTORY ${work}/corpus)
  add_test(NAME fuzz.${reader}
    COMMAND ${target} -runs=${${reader}_runs} -seed=1 -timeout=10 -rss_limit_mb=2048
            -max_total_time=120 -print_final_stats=1 -artifact_prefix=${work}/
            ${work}/corpus ${fuzz_dir}/corpus/${reader} ${${reader}_seeds})
  set_tests_properties(fuzz.${reader} PROPERTIES LABELS fuzz TIMEOUT 300)
endforeach()
