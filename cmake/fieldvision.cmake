# Helpers: one library per module folder, tests beside the code.
#
# fv_module(NAME name DEPS fv_util ... [TEST_DEPS ...] [SRCS a.cc ...])
#   builds library fv_<name> from SRCS (default: every *.cc in the folder that is not a
#   *_test.cc) and, when tests are on, the test program <name>_test from every *_test.cc in the
#   folder (linked to the library, TEST_DEPS and GTest).
function(fv_module)
  cmake_parse_arguments(M "" "NAME" "SRCS;DEPS;TEST_DEPS" ${ARGN})
  set(lib fv_${M_NAME})
  if(NOT M_SRCS)
    file(GLOB M_SRCS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cc)
    list(FILTER M_SRCS EXCLUDE REGEX "_test\\.cc$")
  endif()
  if(NOT M_SRCS)
    message(STATUS "fieldvision: module ${M_NAME} has no sources yet; skipped")
    return()
  endif()
  add_library(${lib} STATIC ${M_SRCS})
  target_include_directories(${lib} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(${lib} PUBLIC ${M_DEPS})
  target_compile_options(${lib} PRIVATE -Wall -Wextra -Wno-unused-parameter)
  # Test dependencies on modules not built yet (e.g. fv_synth) are left out.
  set(test_deps)
  foreach(d ${M_TEST_DEPS})
    if(NOT d MATCHES "^fv_" OR TARGET ${d})
      list(APPEND test_deps ${d})
    endif()
  endforeach()
  if(FV_BUILD_TESTS)
    file(GLOB tests CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*_test.cc)
    if(tests)
      add_executable(${M_NAME}_test ${tests})
      target_link_libraries(${M_NAME}_test PRIVATE ${lib} ${test_deps} fv_testing GTest::gmock
                            GTest::gtest GTest::gtest_main)
      gtest_discover_tests(${M_NAME}_test
        WORKING_DIRECTORY ${CMAKE_BINARY_DIR}
        PROPERTIES ENVIRONMENT "FV_TEST_TMP=${CMAKE_BINARY_DIR}/test-tmp"
        DISCOVERY_TIMEOUT 60)
    endif()
  endif()
endfunction()
