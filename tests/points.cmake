# VDB point caches (io/cache/VdbPointCache) and the file emitter ([[emitters]] type = "file"): the
# cache read back through OpenVDB itself, the emitter fed from CSV and VDB files with its
# effect-file messages, and `tickfx run --format vdb` as a user runs it, checked with vdb_print
# when it is installed. The io/ suites are named io* so that `ctest -R io` selects them. Every
# test writes into a temporary directory of its own. OpenVDB's side (files as other tools write
# them, the caches read back) is tickfx_test_vdbdata's (VDB_TEST_DATA, see CMakeLists.txt).
if(TARGET tickfx_io)
  tickfx_add_test(test_vdb_points ${CMAKE_CURRENT_SOURCE_DIR}/test_vdb_points.cpp
    LIBS tickfx::io VDB_TEST_DATA)
  tickfx_add_test(test_file_emitter ${CMAKE_CURRENT_SOURCE_DIR}/test_file_emitter.cpp
    LIBS tickfx::io VDB_TEST_DATA)
endif()
if(TARGET tickfx_cli)
  tickfx_add_cli_test(test_points_cli ${CMAKE_CURRENT_SOURCE_DIR}/test_points_cli.cpp
    LIBS tickfx::io)
  target_compile_definitions(test_points_cli PRIVATE TICKFX_VERSION="${PROJECT_VERSION}")
  # vdb_print (Debian package libopenvdb-tools, one of scripts/common.sh's packages) lists the
  # caches. Its test is always built: without the tool it fails and names the package, instead of
  # dropping out of the suite unseen.
  find_program(VDB_PRINT vdb_print)
  target_compile_definitions(test_points_cli PRIVATE TICKFX_VDB_PRINT="${VDB_PRINT}")
endif()
