# Libraries of the bag readers (src/io/ros1_bag.cpp, ros2_*.cpp, mcap_reader.cpp), joined in one
# interface target `scfloam_bag_deps`.
# - ROS 1: Debian's librosbag-dev. Its rosbag_storage.pc requires a `pluginlib` .pc that Debian
#   does not ship, and its catkin config files expect a catkin workspace, so the headers and
#   libraries are found by hand. bag.h includes pluginlib (ROS 2's, under /usr/include/pluginlib)
#   and through it class_loader, rcutils, rcpputils: their include dirs are added too.
# - ROS 2: sqlite3; MCAP chunks: zstd and lz4 (frame format).
# - Our own ROS 1 chunk walk (src/io/ros1_bag_check_chunk.cpp): bz2 and lz4 (frame format).
find_package(SQLite3 REQUIRED)
find_package(BZip2 REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
pkg_check_modules(LZ4 REQUIRED IMPORTED_TARGET liblz4)

find_path(ROSBAG_INCLUDE_DIR rosbag/bag.h REQUIRED)
set(_rosbag_include_dirs ${ROSBAG_INCLUDE_DIR})
foreach(sub pluginlib class_loader rcutils rcpputils ament_index_cpp)
  find_path(_dir_${sub} NAMES ${sub} PATHS /usr/include/${sub} NO_DEFAULT_PATH)
  if(_dir_${sub})
    list(APPEND _rosbag_include_dirs ${_dir_${sub}})
  endif()
endforeach()
set(_rosbag_libs "")
foreach(lib rosbag_storage roscpp_serialization rostime cpp_common console_bridge boost_filesystem)
  find_library(ROSBAG_LIB_${lib} ${lib} REQUIRED)
  list(APPEND _rosbag_libs ${ROSBAG_LIB_${lib}})
endforeach()

add_library(scfloam_bag_deps INTERFACE)
target_include_directories(scfloam_bag_deps SYSTEM INTERFACE ${_rosbag_include_dirs})
target_link_libraries(scfloam_bag_deps INTERFACE ${_rosbag_libs} SQLite::SQLite3 BZip2::BZip2 PkgConfig::ZSTD PkgConfig::LZ4)
