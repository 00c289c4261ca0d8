# Every third-party dependency, found once. All come from Debian 12 packages
# (scripts/install-deps.sh); nothing is downloaded at configure time.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)

# LCM has no CMake config on Debian: pkg-config (needs libglib2.0-dev) + lcm-gen.
pkg_check_modules(LCM REQUIRED IMPORTED_TARGET lcm)
find_program(LCM_GEN_EXECUTABLE lcm-gen REQUIRED)
find_program(LCM_LOGPLAYER_EXECUTABLE lcm-logplayer)
find_program(LCM_LOGGER_EXECUTABLE lcm-logger)

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs features2d calib3d video videoio objdetect)
find_package(Ceres REQUIRED)
find_package(octomap REQUIRED)
pkg_check_modules(YAMLCPP REQUIRED IMPORTED_TARGET yaml-cpp)
pkg_check_modules(DC1394 REQUIRED IMPORTED_TARGET libdc1394-2)
pkg_check_modules(OSMESA REQUIRED IMPORTED_TARGET osmesa)
find_package(fastcdr REQUIRED)
find_package(fastrtps REQUIRED)
find_program(FASTDDSGEN_EXECUTABLE fastddsgen)

if(MBSLAM_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(MBSLAM_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()

# octomap's config exports plain variables; wrap them in an imported target.
if(NOT TARGET mbslam::octomap)
  add_library(mbslam::octomap INTERFACE IMPORTED)
  set_target_properties(mbslam::octomap PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${OCTOMAP_INCLUDE_DIRS}"
    INTERFACE_LINK_LIBRARIES "${OCTOMAP_LIBRARIES}")
endif()
