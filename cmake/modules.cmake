include(${CMAKE_CURRENT_LIST_DIR}/precompiled_headers.cmake)

# scfloam_module(<room> DEPS ... [PCH_GROUP name] [FUZZED]): a static library scfloam_<room>
# from src/<room>/*.cpp. Rooms with no sources yet become interface libraries so that
# dependents still configure. PCH_GROUP (default `libraries`): rooms whose dependencies add
# compile definitions share a precompiled header of their own (Open3D defines
# _GLIBCXX_USE_CXX11_ABI, and a header precompiled without it is not used). FUZZED: the room
# holds readers the fuzz/ targets drive; with SCFLOAM_FUZZ it gets libFuzzer's coverage
# instrumentation (only these rooms: instrumenting everything made the sanitizer tests of the
# same tree 2.2x slower) and a precompiled header compiled with it.
set(SCFLOAM_MODULES "" CACHE INTERNAL "")
function(scfloam_module room)
  cmake_parse_arguments(M "FUZZED" "PCH_GROUP" "DEPS" ${ARGN})
  if(NOT M_PCH_GROUP)
    set(M_PCH_GROUP libraries)
  endif()
  set(fuzzed OFF)
  if(M_FUZZED AND SCFLOAM_FUZZ)
    set(fuzzed ON)
    set(M_PCH_GROUP ${M_PCH_GROUP}_fuzzed)
  endif()
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/src/${room}/*.cpp)
  set(target scfloam_${room})
  if(sources)
    add_library(${target} STATIC ${sources})
    target_include_directories(${target} PUBLIC ${CMAKE_SOURCE_DIR}/include PRIVATE ${CMAKE_SOURCE_DIR}/src)
    target_link_libraries(${target} PUBLIC ${M_DEPS})
    if(fuzzed)
      target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
    endif()
    scfloam_precompile(${target} GROUP ${M_PCH_GROUP})
  else()
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE ${CMAKE_SOURCE_DIR}/include)
    target_link_libraries(${target} INTERFACE ${M_DEPS})
  endif()
  set(SCFLOAM_MODULES ${SCFLOAM_MODULES} ${target} CACHE INTERNAL "")
endfunction()

# End-to-end and accuracy suites: whole simulated drives through the odometry / loop closure /
# pipeline, minutes each under the sanitizers. ctest label `long`; scripts/test.sh runs them in
# the plain build only and the sanitizer stage runs the unit tests (`ctest -LE long`).
set(SCFLOAM_LONG_TEST_SUITES Pipeline Degenerate LoopSequence LoopClosure SimOdometry
    CACHE STRING "GoogleTest suites labelled `long` in ctest")
# Suites whose tests share an input the test file makes once per process (Pipeline: a 600-frame
# simulated drive, ~50 CPU-s to simulate; LoopClosure: the keyframes of a drifting drive, four
# tests): ctest runs each such suite as one test, in one process, rather than one process per
# test, each making the input again.
set(SCFLOAM_ONE_PROCESS_TEST_SUITES Pipeline LoopClosure
    CACHE STRING "GoogleTest suites that ctest runs as one test (one process)")

# scfloam_test_suite(<room> LIBS ...): tests/<room>/*.cpp as one GoogleTest program test_<room>.
function(scfloam_test_suite room)
  cmake_parse_arguments(T "" "" "LIBS" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/tests/${room}/*.cpp)
  if(NOT sources)
    return()
  endif()
  # tests/support/tbb_threads.cpp: SCFLOAM_TBB_THREADS caps TBB's threads (scripts/tsan.sh).
  add_executable(test_${room} ${sources} ${CMAKE_SOURCE_DIR}/tests/support/tbb_threads.cpp)
  target_link_libraries(test_${room} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main)
  target_include_directories(test_${room} PRIVATE ${CMAKE_SOURCE_DIR}/src ${CMAKE_SOURCE_DIR}/tests)
  scfloam_precompile(test_${room} GROUP tests HEADERS <gtest/gtest.h>)
  target_compile_definitions(test_${room} PRIVATE
    SCFLOAM_SHARED_DIR="${SCFLOAM_SHARED_DIR}"
    SCFLOAM_BINARY_DIR="${CMAKE_BINARY_DIR}")
  # Suites listed in SCFLOAM_LONG_TEST_SUITES get the ctest label `long`; the rest are the unit
  # tests. Two discoveries of the same program, split by gtest filter; the one-process suites
  # this program holds are a ctest test each, named after the suite.
  set(long_suites ${SCFLOAM_LONG_TEST_SUITES})
  list(REMOVE_ITEM long_suites ${SCFLOAM_ONE_PROCESS_TEST_SUITES})
  list(TRANSFORM long_suites APPEND ".*" OUTPUT_VARIABLE long_patterns)
  list(TRANSFORM SCFLOAM_ONE_PROCESS_TEST_SUITES APPEND ".*" OUTPUT_VARIABLE one_process_patterns)
  string(JOIN ":" long_filter ${long_patterns})
  string(JOIN ":" not_unit_filter ${long_patterns} ${one_process_patterns})
  gtest_discover_tests(test_${room} DISCOVERY_TIMEOUT 60 TEST_FILTER "-${not_unit_filter}"
                       PROPERTIES TIMEOUT 900)
  gtest_discover_tests(test_${room} DISCOVERY_TIMEOUT 60 TEST_FILTER "${long_filter}"
                       PROPERTIES TIMEOUT 900 LABELS long)
  foreach(suite ${SCFLOAM_ONE_PROCESS_TEST_SUITES})
    set(holds_suite FALSE)
    foreach(source ${sources})
      file(STRINGS ${source} lines REGEX "^TEST(_F)?\\(${suite},")
      if(lines)
        set(holds_suite TRUE)
      endif()
    endforeach()
    if(holds_suite)
      add_test(NAME ${suite} COMMAND test_${room} --gtest_filter=${suite}.*)
      set_tests_properties(${suite} PROPERTIES TIMEOUT 900)
      if(suite IN_LIST SCFLOAM_LONG_TEST_SUITES)
        set_tests_properties(${suite} PROPERTIES LABELS long)
      endif()
    endif()
  endforeach()
endfunction()
