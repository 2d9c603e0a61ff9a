# cmake -P script behind the embed.find_package test.
file(REMOVE_RECURSE ${WORK_DIR})

function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGV}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

run(${CMAKE_COMMAND} --install ${TICKFX_BINARY_DIR} --prefix ${WORK_DIR}/prefix)
file(GLOB config ${WORK_DIR}/prefix/lib*/cmake/tickfx/tickfxConfig.cmake)
file(GLOB version ${WORK_DIR}/prefix/lib*/cmake/tickfx/tickfxConfigVersion.cmake)
if(NOT config OR NOT version)
  message(FATAL_ERROR "the install has no tickfxConfig.cmake and tickfxConfigVersion.cmake")
endif()
run(${CMAKE_COMMAND} -S ${EMBED_SOURCE_DIR} -B ${WORK_DIR}/build -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/embed)
message("${last_output}")
