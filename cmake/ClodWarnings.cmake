# Warning and sanitizer flags applied per target, never through global CMAKE_CXX_FLAGS.
function(clod_target_defaults target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wno-unused-parameter)
    if(CLOD_WARNINGS_AS_ERRORS)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  endif()
endfunction()

if(CLOD_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  # Line tables are all a sanitizer report needs (file:line per frame); full debug info made the
  # CI's sanitizer build ~20% slower to compile (measured on src/narrowphase/query.cpp).
  # -O1 (after the build type's -O2, so it wins) for the tests: they compiled 1.5-2.4x faster
  # than at -O2 (GCC 12) and it is the optimisation level the AddressSanitizer documentation
  # suggests. clod's own layers go back to -O2 (src/CMakeLists.txt, clod_layer): their run
  # time is most of the sanitizer pass.
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    add_compile_options(-g1 -O1)
  endif()
  add_link_options(-fsanitize=address,undefined)
endif()
