# The layers point one way: particles/ <- fields/ <- integrators/ <- io/ <- app/. A file of one
# layer includes headers of its own layer or of the layers before it, never of a later one
# (cmake -DSOURCE_DIR=... -P CheckLayers.cmake; fails naming each include that points up).
#
# One composition root is allowed: particles/ParticleSystem.cpp runs a tick, so it is where the
# pool meets the forces, the colliders and the scheme. Its header (the system's public face) only declares them.
cmake_minimum_required(VERSION 3.22)
set(layers particles fields integrators io app)
set(allowed_up
  "particles/ParticleSystem.cpp -> fields/ColliderSet.h"
  "particles/ParticleSystem.cpp -> fields/ForceSet.h"
  "particles/ParticleSystem.cpp -> fields/SpringNetwork.h"
  "particles/ParticleSystem.cpp -> integrators/Integrator.h")

set(problems "")
set(checked 0)
list(LENGTH layers layer_count)
math(EXPR last "${layer_count} - 1")
foreach(rank RANGE ${last})
  list(GET layers ${rank} layer)
  file(GLOB_RECURSE files RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/${layer}/*.h ${SOURCE_DIR}/${layer}/*.cpp)
  foreach(file ${files})
    math(EXPR checked "${checked} + 1")
    file(STRINGS ${SOURCE_DIR}/${file} includes REGEX "^#include \"[a-z]+/")
    foreach(line ${includes})
      string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" target "${line}")
      string(REGEX REPLACE "/.*" "" target_layer "${target}")
      list(FIND layers ${target_layer} target_rank)
      set(edge "${file} -> ${target}")
      if(target_rank GREATER rank AND NOT edge IN_LIST allowed_up)
        string(APPEND problems "  ${file} includes ${target} (${layer}/ is below ${target_layer}/)\n")
      endif()
    endforeach()
  endforeach()
endforeach()
if(checked LESS 100)
  message(FATAL_ERROR "layers: only ${checked} files found under ${SOURCE_DIR}: wrong SOURCE_DIR?")
endif()
if(problems)
  message(FATAL_ERROR "layers: includes that point up (particles <- fields <- integrators <- io <- app):\n${problems}")
endif()
message(STATUS "layers: ${checked} files, every include points down or across")
