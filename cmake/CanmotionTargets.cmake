# Shared build helpers for canmotion.
#
# canmotion_library(NAME DIR [DEPS ...] [PRIVATE_DEPS ...])
#   One static library per folder. Sources are every .cpp below DIR (not in
#   subfolders that are libraries of their own; pass EXCLUDE to skip them).
#   Headers are included as "<folder>/<file>.hpp" from the repository root.

set(CANMOTION_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion)

function(canmotion_apply_flags target)
  target_compile_options(${target} PRIVATE ${CANMOTION_WARNINGS})
  if(CANMOTION_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

if(CANMOTION_SANITIZE STREQUAL "address")
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
elseif(CANMOTION_SANITIZE STREQUAL "thread")
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
elseif(NOT CANMOTION_SANITIZE STREQUAL "")
  message(FATAL_ERROR "CANMOTION_SANITIZE must be '', 'address' or 'thread', not '${CANMOTION_SANITIZE}'")
endif()

if(CANMOTION_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "CANMOTION_FUZZ=ON needs clang: -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang")
  endif()
  # Instrument the libraries for coverage; the fuzz binaries add -fsanitize=fuzzer.
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
elseif(FALSE)
  message(FATAL_ERROR "CANMOTION_SANITIZE must be '', 'address' or 'thread', not '${CANMOTION_SANITIZE}'")
endif()

# ---- optimised product builds ------------------------------------------------
# CANMOTION_LTO (default ON; GCC Release/RelWithDebInfo builds without
# sanitizers or fuzzing): the hot path crosses many small functions in
# different libraries (planner -> controller -> DriveProxy -> SimBus ->
# emulator), so the product programs (canmotion_executable(... LTO)) are
# linked with link-time optimisation and the optimised builds use -O3
# (BENCHMARKS.md, "--sim speed": -O2 -> -O3 + LTO measured before enabling).
# Every object is compiled "fat" (machine code and GIMPLE), so the tests and
# benchmarks still link the ordinary way (-fno-lto): one LTO link per program
# instead of one per test binary keeps the build time of CI.
option(CANMOTION_LTO "Link-time optimisation and -O3 for the product programs (GCC optimised builds)" ON)
set(CANMOTION_LTO_ACTIVE OFF)
if(CANMOTION_LTO AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CANMOTION_SANITIZE STREQUAL ""
   AND NOT CANMOTION_FUZZ AND CMAKE_BUILD_TYPE MATCHES "^(Release|RelWithDebInfo)$")
  set(CANMOTION_LTO_ACTIVE ON)
  string(REGEX REPLACE "-O[0-9s]" "-O3" CMAKE_CXX_FLAGS_RELEASE "${CMAKE_CXX_FLAGS_RELEASE}")
  string(REGEX REPLACE "-O[0-9s]" "-O3" CMAKE_CXX_FLAGS_RELWITHDEBINFO "${CMAKE_CXX_FLAGS_RELWITHDEBINFO}")
  add_compile_options($<$<COMPILE_LANGUAGE:CXX>:-flto=auto> $<$<COMPILE_LANGUAGE:CXX>:-ffat-lto-objects>)
  # GCC 12 at -O3 warns falsely inside libstdc++'s std::string operator+
  # ("memcpy ... may overlap", GCC bug 105329).
  if(CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    add_compile_options($<$<COMPILE_LANGUAGE:CXX>:-Wno-restrict>)
  endif()
  # Executables link with LTO only when they ask for it (property CANMOTION_LTO_LINK).
  add_link_options($<IF:$<BOOL:$<TARGET_PROPERTY:CANMOTION_LTO_LINK>>,-flto=auto,-fno-lto>)
  message(STATUS "canmotion: -O3, and link-time optimisation for the product programs (CANMOTION_LTO=ON)")
endif()

function(canmotion_library name alias)
  cmake_parse_arguments(ARG "" "" "DEPS;PRIVATE_DEPS;EXCLUDE_DIRS" ${ARGN})
  file(GLOB_RECURSE srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  foreach(ex IN LISTS ARG_EXCLUDE_DIRS)
    list(FILTER srcs EXCLUDE REGEX "^${CMAKE_CURRENT_SOURCE_DIR}/${ex}/")
  endforeach()
  if(srcs)
    add_library(${name} STATIC ${srcs})
    target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
    target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
    canmotion_apply_flags(${name})
  else()
    # Header-only until it gains sources.
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(${name} INTERFACE ${ARG_DEPS})
  endif()
  add_library(${alias} ALIAS ${name})
endfunction()

# canmotion_executable(NAME [LTO] SOURCES ... LIBS ...)
# LTO: a product program whose cycle speed matters; linked with link-time
# optimisation when CANMOTION_LTO is active (see above).
function(canmotion_executable name)
  cmake_parse_arguments(ARG "LTO" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS})
  canmotion_apply_flags(${name})
  if(ARG_LTO)
    set_property(TARGET ${name} PROPERTY CANMOTION_LTO_LINK ON)
  endif()
endfunction()
