# cmake -P script behind the embed.find_package test: install tickfx into a scratch prefix, check
# that exactly the public headers are installed and that each compiles alone, build
# samples/embed against the install with find_package(... COMPONENTS effects vdb), and compare
# its state hash with `tickfx run`'s.
cmake_minimum_required(VERSION 3.22)
file(REMOVE_RECURSE ${WORK_DIR})

function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGV}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

function(hash_of text out_var)
  if(NOT text MATCHES "state-hash: ([0-9a-f]+)")
    message(FATAL_ERROR "no state-hash line in:\n${text}")
  endif()
  set(${out_var} ${CMAKE_MATCH_1} PARENT_SCOPE)
endfunction()

set(prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --install ${TICKFX_BINARY_DIR} --prefix ${prefix})
file(GLOB config ${prefix}/lib*/cmake/tickfx/tickfxConfig.cmake)
file(GLOB version ${prefix}/lib*/cmake/tickfx/tickfxConfigVersion.cmake)
if(NOT config OR NOT version)
  message(FATAL_ERROR "the install has no tickfxConfig.cmake and tickfxConfigVersion.cmake")
endif()

# Exactly the listed public headers, no internal one.
include(${SOURCE_DIR}/cmake/PublicHeaders.cmake)
set(expected ${TICKFX_CORE_PUBLIC_HEADERS} ${TICKFX_VDB_PUBLIC_HEADERS} ${TICKFX_EFFECTS_PUBLIC_HEADERS})
list(TRANSFORM expected REPLACE "^include/tickfx/" "")
list(SORT expected)
file(GLOB_RECURSE installed RELATIVE ${prefix}/include/tickfx ${prefix}/include/tickfx/*)
list(SORT installed)
if(NOT installed STREQUAL expected)
  message(FATAL_ERROR "installed headers:\n  ${installed}\nexpected (cmake/PublicHeaders.cmake):\n  ${expected}")
endif()

# Two checks on each header's text:
# - Only include/ goes on a host's include path: installed headers include each other as
#   <tickfx/...>, never by a bare "particles/..." path that would need include/tickfx there too.
# - Below, each header compiles with <Eigen/Core> precompiled: parsing it was 1.4 s of a
#   header's 2.5, most of this test's time. Then a header that names Eigen but includes none of
#   it would still compile, so each header that names Eigen must reach an <Eigen/...> include of
#   its own or through the tickfx headers it includes.
set(eigen_reached "")
set(eigen_named "")
foreach(header ${installed})
  file(READ ${prefix}/include/tickfx/${header} text)
  string(REGEX MATCHALL "[^\n]*#include \"[^\n]*" bare "${text}")
  if(bare)
    message(FATAL_ERROR "include/tickfx/${header} includes by a bare path:\n${bare}")
  endif()
  string(REGEX MATCHALL "#include <tickfx/[^>]+>" deps_${header} "${text}")
  list(TRANSFORM deps_${header} REPLACE "#include <tickfx/([^>]+)>" "\\1")
  if(text MATCHES "#include <Eigen/")
    list(APPEND eigen_reached ${header})
  endif()
  if(text MATCHES "Eigen::|EIGEN_")
    list(APPEND eigen_named ${header})
  endif()
endforeach()
set(grown TRUE)
while(grown)
  set(grown FALSE)
  foreach(header ${installed})
    if(header IN_LIST eigen_reached)
      continue()
    endif()
    foreach(dep ${deps_${header}})
      if(dep IN_LIST eigen_reached)
        list(APPEND eigen_reached ${header})
        set(grown TRUE)
        break()
      endif()
    endforeach()
  endforeach()
endwhile()
foreach(header ${eigen_named})
  if(NOT header IN_LIST eigen_reached)
    message(FATAL_ERROR "include/tickfx/${header} names Eigen but includes none of its headers, "
                        "itself or through the tickfx headers it includes")
  endif()
endforeach()

# Each header alone (twice: include guards), as a host includes it, and the umbrella.
set(headers_dir ${WORK_DIR}/headers)
set(sources "")
foreach(header ${installed})
  string(MAKE_C_IDENTIFIER ${header} name)
  file(WRITE ${headers_dir}/${name}.cpp "#include <tickfx/${header}>\n#include <tickfx/${header}>\n")
  list(APPEND sources ${name}.cpp)
endforeach()
file(WRITE ${headers_dir}/CMakeLists.txt "cmake_minimum_required(VERSION 3.22)
project(tickfx_headers LANGUAGES CXX)
find_package(tickfx 0.3 CONFIG REQUIRED COMPONENTS effects vdb)
add_library(headers OBJECT ${sources})
target_link_libraries(headers PRIVATE tickfx::effects)
target_precompile_headers(headers PRIVATE <Eigen/Core>)
")
run(${CMAKE_COMMAND} -S ${headers_dir} -B ${headers_dir}/build -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_PREFIX_PATH=${prefix})
run(${CMAKE_COMMAND} --build ${headers_dir}/build)

# A component the package does not have is refused by name.
file(WRITE ${WORK_DIR}/nocomponent/CMakeLists.txt "cmake_minimum_required(VERSION 3.22)
project(nocomponent LANGUAGES CXX)
find_package(tickfx 0.3 CONFIG REQUIRED COMPONENTS usd)
")
execute_process(COMMAND ${CMAKE_COMMAND} -S ${WORK_DIR}/nocomponent -B ${WORK_DIR}/nocomponent/build
                -G ${GENERATOR} -DCMAKE_PREFIX_PATH=${prefix}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "tickfx has no component 'usd' \\(components: effects, vdb\\)")
  message(FATAL_ERROR "COMPONENTS usd was not refused by name:\n${out}\n${err}")
endif()

# The sample a pipeline engineer copies, against the install, and the CLI on the same effect.
run(${CMAKE_COMMAND} -S ${EMBED_SOURCE_DIR} -B ${WORK_DIR}/build -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
    -DCMAKE_PREFIX_PATH=${prefix})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/embed ${SOURCE_DIR}/samples/fountain.toml)
set(embed_output "${last_output}")
hash_of("${embed_output}" embed_hash)
run(${TICKFX_CLI} run ${SOURCE_DIR}/samples/fountain.toml --fps 30000/1001 --seconds 5 --hash
    --format none --quiet)
hash_of("${last_output}" cli_hash)
message("${embed_output}")
if(NOT embed_hash STREQUAL cli_hash)
  message(FATAL_ERROR "embed's state hash ${embed_hash} differs from tickfx run's ${cli_hash}")
endif()
message("embed and tickfx run agree: ${embed_hash}")
