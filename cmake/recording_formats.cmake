# The readers of bags and MCAP files (src/io/formats, docs/data_contract.md
# "Formats"): SQLite for rosbag2 .db3, zstd and lz4 for compressed MCAP
# chunks and zlib for their CRC (required), and, when Debian's librosbag-storage-dev is installed,
# the ROS project's reader for ROS 1 bags (optional: without it a ROS 1 bag
# is named and refused).
#
# They are the reader module libgravcal_formats.so (src/io/formats/
# reader_module.h), loaded with dlopen the first time a bag or MCAP file is
# opened, so that a CSV calibration loads none of these libraries. It is
# built beside the tool (<build>/libgravcal_formats.so) and installed in
# <libdir>/gravcal (and beside the Python extension by the python component).
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
set(_gravcal_formats_dir ${CMAKE_CURRENT_SOURCE_DIR}/src/io/formats)
add_library(gravcal_formats MODULE ${_gravcal_formats_dir}/mcap_file.cc
  ${_gravcal_formats_dir}/ros1_bag.cc ${_gravcal_formats_dir}/ros1_bag_structure.cc
  ${_gravcal_formats_dir}/rosbag2_sqlite.cc ${_gravcal_formats_dir}/reader_module_entry.cc)
set_target_properties(gravcal_formats PROPERTIES
  PREFIX "lib" LIBRARY_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}
  CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
target_include_directories(gravcal_formats PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src
  ${CMAKE_CURRENT_SOURCE_DIR}/include)
target_include_directories(gravcal_formats SYSTEM PRIVATE
  ${GRAVCAL_SQLITE3_INCLUDE} ${GRAVCAL_ZSTD_INCLUDE} ${GRAVCAL_LZ4_INCLUDE})
target_link_libraries(gravcal_formats PRIVATE Eigen3::Eigen
  ${GRAVCAL_SQLITE3_LIBRARY} ${GRAVCAL_ZSTD_LIBRARY} ${GRAVCAL_LZ4_LIBRARY} ${GRAVCAL_ZLIB_LIBRARY})
target_compile_options(gravcal_formats PRIVATE -Wall -Wextra)
target_compile_definitions(gravcal_formats PRIVATE GRAVCAL_VERSION="${PROJECT_VERSION}")
target_compile_features(gravcal_formats PRIVATE cxx_std_17)
# Whatever builds the library builds the module (tests read bags through it).
add_dependencies(${GRAVCAL_COMPILE_TARGET} gravcal_formats)
target_link_libraries(${GRAVCAL_COMPILE_TARGET} PRIVATE ${CMAKE_DL_LIBS})
# Where the library looks for the module (reader_module.cc).
set_property(SOURCE ${_gravcal_formats_dir}/reader_module.cc APPEND PROPERTY COMPILE_DEFINITIONS
  GRAVCAL_MODULE_BUILD_DIR="${PROJECT_BINARY_DIR}"
  GRAVCAL_MODULE_INSTALL_DIR="${CMAKE_INSTALL_FULL_LIBDIR}/gravcal"
  GRAVCAL_MODULE_INSTALL_LIBDIR="${CMAKE_INSTALL_LIBDIR}")
install(TARGETS gravcal_formats LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/gravcal)

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
    target_link_libraries(gravcal_formats PRIVATE ${_gravcal_rosbag_libraries})
  else()
    message(STATUS "ROS 1 bags: librosbag_storage not found, bags are refused")
  endif()
endif()
