# The readers of bags and MCAP files (src/io/formats, docs/data_contract.md
# "Formats"): SQLite for rosbag2 .db3, zstd and lz4 for compressed MCAP
# chunks and zlib for their CRC (required), and, when Debian's librosbag-storage-dev is installed,
# the ROS project's reader for ROS 1 bags (optional: without it a ROS 1 bag
# is named and refused).
find_library(GRAVCAL_SQLITE3_LIBRARY sqlite3)
find_path(GRAVCAL_SQLITE3_INCLUDE sqlite3.h)
find_library(GRAVCAL_ZSTD_LIBRARY zstd)
find_path(GRAVCAL_ZSTD_INCLUDE zstd.h)
find_library(GRAVCAL_ZLIB_LIBRARY z)
find_library(GRAVCAL_LZ4_LIBRARY lz4)
find_path(GRAVCAL_LZ4_INCLUDE lz4frame.h)
foreach(var GRAVCAL_ZLIB_LIBRARY GRAVCAL_SQLITE3_LIBRARY GRAVCAL_SQLITE3_INCLUDE GRAVCAL_ZSTD_LIBRARY
            GRAVCAL_ZSTD_INCLUDE GRAVCAL_LZ4_LIBRARY GRAVCAL_LZ4_INCLUDE)
  if(NOT ${var})
    message(FATAL_ERROR "${var} not found: install libsqlite3-dev libzstd-dev liblz4-dev zlib1g-dev")
  endif()
endforeach()
target_include_directories(${GRAVCAL_COMPILE_TARGET} SYSTEM PRIVATE
  ${GRAVCAL_SQLITE3_INCLUDE} ${GRAVCAL_ZSTD_INCLUDE} ${GRAVCAL_LZ4_INCLUDE})
target_link_libraries(${GRAVCAL_COMPILE_TARGET} PRIVATE
  ${GRAVCAL_SQLITE3_LIBRARY} ${GRAVCAL_ZSTD_LIBRARY} ${GRAVCAL_LZ4_LIBRARY} ${GRAVCAL_ZLIB_LIBRARY})

# Debian's rosbag_storage headers include the ROS 2 pluginlib, class_loader,
# rcpputils, rcutils and ament_index_cpp headers, each in its own folder.
option(GRAVCAL_WITH_ROSBAG "Read ROS 1 bags with librosbag_storage when found" ON)
if(GRAVCAL_WITH_ROSBAG)
  find_path(GRAVCAL_ROSBAG_INCLUDE rosbag/bag.h)
  set(_gravcal_rosbag_found TRUE)
  set(_gravcal_rosbag_libraries)
  # roslz4 and bz2: src/io/formats/ros1_bag_structure.cc uncompresses each
  # chunk as rosbag will, to check it before rosbag reads it.
  foreach(lib rosbag_storage roscpp_serialization rostime cpp_common console_bridge
              class_loader ament_index_cpp roslz4 bz2)
    find_library(GRAVCAL_ROS_${lib}_LIBRARY ${lib})
    if(NOT GRAVCAL_ROS_${lib}_LIBRARY)
      set(_gravcal_rosbag_found FALSE)
    endif()
    list(APPEND _gravcal_rosbag_libraries ${GRAVCAL_ROS_${lib}_LIBRARY})
  endforeach()
  set(_gravcal_rosbag_flags)
  foreach(dir pluginlib class_loader rcpputils rcutils ament_index_cpp)
    if(NOT EXISTS /usr/include/${dir})
      set(_gravcal_rosbag_found FALSE)
    endif()
    list(APPEND _gravcal_rosbag_flags -isystem /usr/include/${dir})
  endforeach()
  if(GRAVCAL_ROSBAG_INCLUDE AND _gravcal_rosbag_found)
    message(STATUS "ROS 1 bags: librosbag_storage")
    set(_gravcal_rosbag_sources ${CMAKE_CURRENT_SOURCE_DIR}/src/io/formats/ros1_bag.cc
                                ${CMAKE_CURRENT_SOURCE_DIR}/src/io/formats/ros1_bag_structure.cc)
    set_property(SOURCE ${_gravcal_rosbag_sources}
      APPEND PROPERTY COMPILE_OPTIONS ${_gravcal_rosbag_flags})
    set_property(SOURCE ${_gravcal_rosbag_sources}
      APPEND PROPERTY COMPILE_DEFINITIONS GRAVCAL_HAVE_ROSBAG)
    target_link_libraries(${GRAVCAL_COMPILE_TARGET} PRIVATE ${_gravcal_rosbag_libraries})
  else()
    message(STATUS "ROS 1 bags: librosbag_storage not found, bags are refused")
  endif()
endif()
