# Vector fields through the command line: `tickfx bake-field`, and `run`/`check`/`determinism`
# with field files that do not load. Reads the baked files back with VectorField (tickfx::vdb) and
# writes a scalar grid with OpenVDB itself (VDB_TEST_DATA, see CMakeLists.txt); everything
# goes into a temporary directory.
if(TARGET tickfx_cli AND TARGET tickfx_vdb)
  tickfx_add_cli_test(test_cli_fields ${CMAKE_CURRENT_SOURCE_DIR}/test_cli_fields.cpp
    LIBS tickfx::vdb VDB_TEST_DATA)
endif()
