# OpenVDB vector fields (fields/VectorField, fields/AnalyticField): only when tickfx_vdb is built.
# The test writes its .vdb files into a temporary directory of its own. What the tests need of
# OpenVDB itself (files of every layout, PointAdvect as the oracle) is tickfx_test_vdbdata's
# (VDB_TEST_DATA, see CMakeLists.txt).
if(TARGET tickfx_vdb)
  tickfx_add_test(test_vdb_field ${CMAKE_CURRENT_SOURCE_DIR}/test_vdb_field.cpp
    LIBS tickfx::vdb VDB_TEST_DATA)
endif()
if(TARGET tickfx_vdb)
  tickfx_add_test(test_vdb_advect ${CMAKE_CURRENT_SOURCE_DIR}/test_vdb_advect.cpp
    LIBS tickfx::vdb VDB_TEST_DATA)
endif()
