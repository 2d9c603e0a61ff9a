# VDB point caches (io/VdbPointCache): the cache read back through OpenVDB itself. Suites are
# named io* so that `ctest -R io` selects them. Every test writes into a temporary directory of
# its own.
if(TARGET tickfx_io)
  tickfx_add_test(test_vdb_points ${CMAKE_CURRENT_SOURCE_DIR}/test_vdb_points.cpp
    LIBS tickfx::io OpenVDB::openvdb)
endif()
