# Configures, builds and tests the FMM core standalone with AddressSanitizer and
# UndefinedBehaviorSanitizer (run by the ctest entry fmm.sanitize, unittest/fmm/CMakeLists.txt):
#   cmake -DSRC=<src/fmm> -DBIN=<build dir> -DGENERATOR=<generator> [-DCXX=<compiler>] [-DLAUNCHER=ccache] -P sanitize.cmake
# Any sanitizer report aborts the test executable (-fno-sanitize-recover=all), so a memory error
# or undefined behaviour fails this test. GCFMM_TEST_SMALL reduces the problem sizes of the
# tests that read it.
set(flags "-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer")
set(args -S ${SRC} -B ${BIN} -G ${GENERATOR} -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS=${flags}"
         "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined" -DGCFMM_SANITIZER_TEST=OFF -DGCFMM_BENCH=OFF)
if(CXX)
  list(APPEND args -DCMAKE_CXX_COMPILER=${CXX})
endif()
if(LAUNCHER)
  list(APPEND args -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
execute_process(COMMAND ${CMAKE_COMMAND} ${args} RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "sanitizer build: configure failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BIN} -j2 RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "sanitizer build: build failed")
endif()
set(ENV{GCFMM_TEST_SMALL} 1)
set(ENV{ASAN_OPTIONS} "detect_leaks=1:abort_on_error=0")
set(ENV{UBSAN_OPTIONS} "print_stacktrace=1")
execute_process(COMMAND ${CMAKE_CTEST_COMMAND} --test-dir ${BIN} --output-on-failure RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "sanitizer build: tests failed (see the reports above)")
endif()
