# Project-wide flags. -ffp-contract=off keeps results bit-identical whatever the compiler fuses;
# never -ffast-math (shared/PLATFORM.md: determinism at any thread count). -fno-trapping-math changes no
# value (nothing here unmasks FP exceptions); it lets the vectorizer turn a select between computed
# values into a blend instead of keeping a branch (e.g. the unit normals of cylinder_normals.cpp).
add_library(rivulet_options INTERFACE)
target_compile_options(rivulet_options INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  -ffp-contract=off -fno-math-errno -fno-trapping-math>)
# Position-independent code (for the Python module) would otherwise let every exported function be
# interposed, and so not inlined within its own file.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(rivulet_options INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-fno-semantic-interposition>)
endif()
if(RIVULET_SANITIZE STREQUAL "address")
  # vptr is off: oneTBB's flow-graph headers destroy a task and then downcast it (a known false positive).
  target_compile_options(rivulet_options INTERFACE -fsanitize=address,undefined -fno-sanitize=vptr
                         -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(rivulet_options INTERFACE -fsanitize=address,undefined -fno-sanitize=vptr)
elseif(RIVULET_SANITIZE STREQUAL "thread")
  target_compile_options(rivulet_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(rivulet_options INTERFACE -fsanitize=thread)
elseif(RIVULET_SANITIZE STREQUAL "fuzz")
  # ASan+UBSan as above, plus libFuzzer's coverage hooks in every library so the fuzzer sees the readers'
  # branches; only the fuzz targets link libFuzzer's main (tests/fuzz, docs/fuzzing.md).
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "RIVULET_SANITIZE=fuzz needs Clang (libFuzzer): configure with CC=clang CXX=clang++")
  endif()
  # A Release build keeps line tables (cheap next to -g) so that crash stacks name file and line.
  target_compile_options(rivulet_options INTERFACE -fsanitize=address,undefined,fuzzer-no-link
                         -fno-sanitize=vptr -fno-omit-frame-pointer -fno-sanitize-recover=undefined
                         $<$<CONFIG:Release,MinSizeRel>:-gline-tables-only>)
  target_link_options(rivulet_options INTERFACE -fsanitize=address,undefined -fno-sanitize=vptr)
elseif(NOT RIVULET_SANITIZE STREQUAL "")
  message(FATAL_ERROR "RIVULET_SANITIZE must be '', 'address', 'thread' or 'fuzz'")
endif()

# Sources of one folder library: every .cpp under it (one responsibility per file, so lists would only churn).
function(rivulet_folder_sources out_var dir)
  file(GLOB_RECURSE srcs CONFIGURE_DEPENDS ${dir}/*.cpp)
  set(${out_var} ${srcs} PARENT_SCOPE)
endfunction()
