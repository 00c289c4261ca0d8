# Warnings for the project's own targets (applied through mbslam_target_defaults).
set(MBSLAM_WARNING_FLAGS -Wall -Wextra -Wno-unused-parameter)
if(MBSLAM_WERROR)
  list(APPEND MBSLAM_WARNING_FLAGS -Werror)
endif()

if(MBSLAM_SANITIZE)
  message(STATUS "mbslam: AddressSanitizer + UBSan enabled")
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
