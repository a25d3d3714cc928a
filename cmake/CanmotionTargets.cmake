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

# canmotion_executable(NAME SOURCES ... LIBS ...)
function(canmotion_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS})
  canmotion_apply_flags(${name})
endfunction()
