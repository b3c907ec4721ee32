# Project-wide flags. -ffp-contract=off keeps results bit-identical whatever the compiler fuses;
# never -ffast-math (shared/PLATFORM.md: determinism at any thread count). -fno-trapping-math changes no
# value (nothing here unmasks FP exceptions); it lets the vectorizer turn a select between computed
# values into a blend instead of keeping a branch (e.g. the unit normals of cylinder_normals.cpp).
add_library(rivulet_options INTERFACE)
target_compile_options(rivulet_options INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  -ffp-contract=off -fno-math-errno -fno-trapping-math>)
if(RIVULET_SANITIZE STREQUAL "address")
  # vptr is off: oneTBB's flow-graph headers destroy a task and then downcast it (a known false positive).
  target_compile_options(rivulet_options INTERFACE -fsanitize=address,undefined -fno-sanitize=vptr
                         -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(rivulet_options INTERFACE -fsanitize=address,undefined -fno-sanitize=vptr)
elseif(RIVULET_SANITIZE STREQUAL "thread")
  target_compile_options(rivulet_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(rivulet_options INTERFACE -fsanitize=thread)
elseif(NOT RIVULET_SANITIZE STREQUAL "")
  message(FATAL_ERROR "RIVULET_SANITIZE must be '', 'address' or 'thread'")
endif()

# Sources of one folder library: every .cpp under it (one responsibility per file, so lists would only churn).
function(rivulet_folder_sources out_var dir)
  file(GLOB_RECURSE srcs CONFIGURE_DEPENDS ${dir}/*.cpp)
  set(${out_var} ${srcs} PARENT_SCOPE)
endfunction()
