# Precompiled headers: the heavy headers nearly every file includes (Eigen through types.hpp,
# GoogleTest in the tests, CLI11 in the commands: 1.5-4.4 s of parsing per file) are parsed
# once instead of once per file. One precompiled header serves all libraries and one all test
# programs (REUSE_FROM): one per target cost more to build than it saved. -DSCFLOAM_PCH=OFF
# builds without them, which is how to check that every file includes what it uses.
option(SCFLOAM_PCH "Precompile the common heavy headers" ON)
set(SCFLOAM_PCH_HEADERS <filesystem> <memory> <string> <vector> <Eigen/Core> <Eigen/Geometry>)

# scfloam_precompile(<target> GROUP <name> [HEADERS ...]): the first target of a group builds
# the group's precompiled header (the common list plus HEADERS); later ones reuse it.
function(scfloam_precompile target)
  cmake_parse_arguments(P "" "GROUP" "HEADERS" ${ARGN})
  if(NOT SCFLOAM_PCH)
    return()
  endif()
  get_property(base GLOBAL PROPERTY SCFLOAM_PCH_BASE_${P_GROUP})
  if(base)
    target_precompile_headers(${target} REUSE_FROM ${base})
  else()
    target_precompile_headers(${target} PRIVATE ${SCFLOAM_PCH_HEADERS} ${P_HEADERS})
    set_property(GLOBAL PROPERTY SCFLOAM_PCH_BASE_${P_GROUP} ${target})
  endif()
endfunction()
