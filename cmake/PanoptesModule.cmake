# panoptes_module(NAME SOURCES ... [DEPS ...] [PRIVATE_DEPS ...])
# One static library per module, target panoptes_<NAME>, alias panoptes::<NAME>.
# Headers are included as "<module>/<header>.hpp" from src/.
function(panoptes_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(panoptes_${name} STATIC ${ARG_SOURCES})
  if(PANOPTES_UNITY AND NOT name IN_LIST PANOPTES_HOT_MODULES)
    set_target_properties(panoptes_${name} PROPERTIES UNITY_BUILD ON)
  endif()
  add_library(panoptes::${name} ALIAS panoptes_${name})
  target_include_directories(panoptes_${name} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(panoptes_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
endfunction()

# panoptes_test(NAME SOURCES ... [DEPS ...] [LABELS ...] [TIMEOUT s])
# A GoogleTest executable whose cases are registered with ctest one by one.
function(panoptes_test name)
  if(NOT PANOPTES_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 120)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  # Optimizing gtest-heavy test bodies at -O3 was ~40 % of a clean build's compile time (CI budget);
  # the code under test lives in the libraries, which keep the full optimization.
  if(CMAKE_BUILD_TYPE STREQUAL "Release")
    target_compile_options(${name} PRIVATE -O1)
  endif()
  if(PANOPTES_UNITY)
    set_target_properties(${name} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  endif()
  panoptes_precompile_test_headers(${name})
  gtest_discover_tests(${name}
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}
    PROPERTIES TIMEOUT ${ARG_TIMEOUT} LABELS "${ARG_LABELS}"
    DISCOVERY_TIMEOUT 60)
endfunction()

# panoptes_bench(NAME SOURCES ... [DEPS ...]): a Google Benchmark program run by scripts/bench.
function(panoptes_bench name)
  if(NOT PANOPTES_BUILD_BENCH)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} benchmark::benchmark)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bench)
endfunction()
