# OpenVDB vector fields (fields/VectorField, fields/AnalyticField): only when tickfx_vdb is built.
# The test writes its .vdb files into a temporary directory of its own.
if(TARGET tickfx_vdb)
  tickfx_add_test(test_vdb_field ${CMAKE_CURRENT_SOURCE_DIR}/test_vdb_field.cpp
    LIBS tickfx::vdb OpenVDB::openvdb)
endif()
if(TARGET tickfx_vdb)
  tickfx_add_test(test_vdb_advect ${CMAKE_CURRENT_SOURCE_DIR}/test_vdb_advect.cpp
    LIBS tickfx::vdb OpenVDB::openvdb)
endif()
