# Test helpers. Labels: unit (codec/unit/property), loop (deterministic
# master+emulator runs on the SimBus with a virtual clock), vcan (real
# SocketCAN, inside tools/vcan-vm when the host has no AF_CAN), fuzz.
include(GoogleTest)
find_package(GTest REQUIRED)

# canmotion_gtest(NAME SOURCES ... LIBS ... [LABEL unit|loop] [TIMEOUT s])
# One gtest binary; every TEST() becomes its own ctest test.
function(canmotion_gtest name)
  if(CANMOTION_FUZZ)
    return()  # a fuzz build (clang, instrumented) builds only fuzz targets
  endif()
  cmake_parse_arguments(ARG "" "LABEL;TIMEOUT" "SOURCES;LIBS" ${ARGN})
  if(NOT ARG_LABEL)
    set(ARG_LABEL unit)
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main Threads::Threads)
  canmotion_apply_flags(${name})
  gtest_discover_tests(${name}
    DISCOVERY_MODE PRE_TEST
    PROPERTIES LABELS ${ARG_LABEL} TIMEOUT ${ARG_TIMEOUT})
endfunction()

# canmotion_vcan_test(NAME COMMAND cmd args... [CHECK cmd args...] [IFACES n] [TIMEOUT s])
# Runs COMMAND on real SocketCAN with vcan0..vcan<n-1> up, through
# tests/vcan/run-vcan-test (VM when the host has no vcan). A candump -L trace of
# every vcan interface is kept in ${CMAKE_BINARY_DIR}/vcan-artifacts/NAME/.
# COMMAND and CHECK see CANMOTION_TRACE (the candump -L log; complete when
# CHECK runs), CANMOTION_ARTIFACTS (that folder), CANMOTION_BUILD_DIR and
# CANMOTION_IFACES. CHECK runs after COMMAND succeeded and candump stopped.
function(canmotion_vcan_test name)
  if(CANMOTION_FUZZ)
    return()  # a fuzz build (clang, instrumented) builds only fuzz targets
  endif()
  cmake_parse_arguments(ARG "" "IFACES;TIMEOUT" "COMMAND;CHECK" ${ARGN})
  if(ARG_CHECK)
    set(check_args ::check:: ${ARG_CHECK})
  endif()
  if(NOT ARG_IFACES)
    set(ARG_IFACES 1)
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 600)
  endif()
  add_test(NAME ${name}
    COMMAND ${PROJECT_SOURCE_DIR}/tests/vcan/run-vcan-test
            --name ${name} --ifaces ${ARG_IFACES}
            --artifacts ${CMAKE_BINARY_DIR}/vcan-artifacts/${name}
            --build-dir ${CMAKE_BINARY_DIR}
            -- ${ARG_COMMAND} ${check_args}
    WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
  # One vcan test at a time, whatever ctest's -j: on a host with vcan they
  # all use vcan0.. (two at once would see each other's frames), and in
  # tools/vcan-vm two emulated VMs on a 2-core machine starved the Python peer
  # (CI of 38b0f64: vcan.peer.boot_enable_move's TPDOs 0.45 s late, a
  # following-error fault in the middle of the move).
  set_tests_properties(${name} PROPERTIES LABELS vcan TIMEOUT ${ARG_TIMEOUT} RESOURCE_LOCK canmotion_vcan)
endfunction()

# canmotion_benchmark(NAME SOURCES ... LIBS ...): Google Benchmark program,
# built but never run as a test (figures go to BENCHMARKS.md).
function(canmotion_benchmark name)
  if(CANMOTION_FUZZ)
    return()  # a fuzz build (clang, instrumented) builds only fuzz targets
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  if(NOT CANMOTION_BUILD_BENCHMARKS)
    return()
  endif()
  find_package(benchmark REQUIRED)
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} benchmark::benchmark Threads::Threads)
  canmotion_apply_flags(${name})
endfunction()

# canmotion_fuzz(NAME SOURCES ... LIBS ... [SECONDS n] [SEEDS dir ...])
# libFuzzer target (clang only, CANMOTION_FUZZ=ON). Runs as a ctest test
# (label fuzz) for a bounded time. SEEDS: seed corpus folders, read only
# (libFuzzer writes new inputs to the first folder it is given, which is
# ${CMAKE_CURRENT_BINARY_DIR}/NAME-corpus).
function(canmotion_fuzz name)
  cmake_parse_arguments(ARG "" "SECONDS" "SOURCES;LIBS;SEEDS" ${ARGN})
  if(NOT CANMOTION_FUZZ)
    return()
  endif()
  if(NOT ARG_SECONDS)
    set(ARG_SECONDS 30)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_compile_options(${name} PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_options(${name} PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_libraries(${name} PRIVATE ${ARG_LIBS})
  set(corpus)
  if(ARG_SEEDS)
    set(corpus ${CMAKE_CURRENT_BINARY_DIR}/${name}-corpus)
    file(MAKE_DIRECTORY ${corpus})
    list(APPEND corpus ${ARG_SEEDS})
  endif()
  add_test(NAME ${name} COMMAND ${name} -max_total_time=${ARG_SECONDS} -rss_limit_mb=2048 -print_final_stats=1 ${corpus})
  set_tests_properties(${name} PROPERTIES LABELS fuzz TIMEOUT ${ARG_SECONDS}0)
endfunction()
