# scfloam_module(<room> DEPS ...): a static library scfloam_<room> from src/<room>/*.cpp.
# Rooms with no sources yet become interface libraries so that dependents still configure.
set(SCFLOAM_MODULES "" CACHE INTERNAL "")
function(scfloam_module room)
  cmake_parse_arguments(M "" "" "DEPS" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/src/${room}/*.cpp)
  set(target scfloam_${room})
  if(sources)
    add_library(${target} STATIC ${sources})
    target_include_directories(${target} PUBLIC ${CMAKE_SOURCE_DIR}/include PRIVATE ${CMAKE_SOURCE_DIR}/src)
    target_link_libraries(${target} PUBLIC ${M_DEPS})
  else()
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE ${CMAKE_SOURCE_DIR}/include)
    target_link_libraries(${target} INTERFACE ${M_DEPS})
  endif()
  set(SCFLOAM_MODULES ${SCFLOAM_MODULES} ${target} CACHE INTERNAL "")
endfunction()

# scfloam_test_suite(<room> LIBS ...): tests/<room>/*.cpp as one GoogleTest program test_<room>.
function(scfloam_test_suite room)
  cmake_parse_arguments(T "" "" "LIBS" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/tests/${room}/*.cpp)
  if(NOT sources)
    return()
  endif()
  add_executable(test_${room} ${sources})
  target_link_libraries(test_${room} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main)
  target_include_directories(test_${room} PRIVATE ${CMAKE_SOURCE_DIR}/src ${CMAKE_SOURCE_DIR}/tests)
  target_compile_definitions(test_${room} PRIVATE
    SCFLOAM_SHARED_DIR="${SCFLOAM_SHARED_DIR}"
    SCFLOAM_BINARY_DIR="${CMAKE_BINARY_DIR}")
  gtest_discover_tests(test_${room} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 900)
endfunction()
