# Shared helpers for costar's per-concept CMakeLists.

# Warnings for the project's own code (third-party headers are included as SYSTEM).
function(costar_warnings target)
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
      -Wold-style-cast -Woverloaded-virtual -Wno-unused-parameter
      -Wno-missing-field-initializers>
    # GCC 12's -Wrestrict fires inside libstdc++ on `"'" + std::string(...)` (GCC bug 105329, a
    # false positive fixed in GCC 13): off for GCC before 13 only.
    $<$<AND:$<CXX_COMPILER_ID:GNU>,$<VERSION_LESS:$<CXX_COMPILER_VERSION>,13>>:-Wno-restrict>)
endfunction()

# costar_library(NAME SOURCES ... [DEPS ...] [PRIVATE_DEPS ...])
# Defines costar_<NAME>, with the repository root as its include root so headers read
# as #include "bt/node.h".
function(costar_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(costar_${name} ${ARG_SOURCES})
  target_include_directories(costar_${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(costar_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  costar_warnings(costar_${name})
endfunction()

# In a COSTAR_SANITIZE build: the sanitizers' default runtime options, linked into an executable.
function(costar_sanitizer_options target)
  if(TARGET costar_sanitizer_options)
    target_link_libraries(${target} PRIVATE costar_sanitizer_options)
  endif()
endfunction()

# costar_test(NAME SOURCES ... DEPS ... [LABELS ...]): a GoogleTest executable registered with
# CTest. The label "sanitize" puts it in the subset run under the sanitizers in scripts/test.sh
# (target sanitize_tests, ctest -L sanitize).
function(costar_test name)
  if(NOT COSTAR_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main GTest::gmock)
  # A temporary folder of its own per test process (cmake/test_private_tmpdir.cpp).
  if(NOT TARGET costar_test_private_tmpdir)
    add_library(costar_test_private_tmpdir OBJECT ${PROJECT_SOURCE_DIR}/cmake/test_private_tmpdir.cpp)
  endif()
  target_link_libraries(${name} PRIVATE costar_test_private_tmpdir)
  costar_warnings(${name})
  costar_sanitizer_options(${name})
  if("sanitize" IN_LIST ARG_LABELS)
    set_property(GLOBAL APPEND PROPERTY COSTAR_SANITIZE_TESTS ${name})
  endif()
  include(GoogleTest)
  gtest_discover_tests(${name} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES LABELS "${ARG_LABELS}" DISCOVERY_TIMEOUT 60)
endfunction()
