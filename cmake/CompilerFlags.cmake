# Warnings for the project's own targets (applied through mbslam_target_defaults).
set(MBSLAM_WARNING_FLAGS -Wall -Wextra -Wno-unused-parameter)
if(MBSLAM_WERROR)
  list(APPEND MBSLAM_WARNING_FLAGS -Werror)
endif()

if(MBSLAM_SANITIZE STREQUAL "address")
  # AddressSanitizer alone (LeakSanitizer included), e.g. for long leak runs.
  message(STATUS "mbslam: AddressSanitizer enabled")
  add_compile_options(-fsanitize=address -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address)
elseif(MBSLAM_SANITIZE)
  message(STATUS "mbslam: AddressSanitizer + UBSan enabled")
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()

# Fuzzing (test/fuzz): coverage for libFuzzer, ASan and UBSan on every project target;
# the fuzz executables add -fsanitize=fuzzer (its main) when they link.
set(MBSLAM_FUZZ_LIBFUZZER OFF)
if(MBSLAM_BUILD_FUZZ)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(STATUS "mbslam: fuzz targets with libFuzzer, ASan and UBSan")
    set(MBSLAM_FUZZ_LIBFUZZER ON)
    add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                        -fno-sanitize-recover=undefined)
    add_link_options(-fsanitize=address,undefined)
  else()
    message(WARNING "mbslam: MBSLAM_BUILD_FUZZ needs clang (CMAKE_CXX_COMPILER=clang++); "
                    "the fuzz targets are built as corpus replayers instead")
  endif()
endif()
