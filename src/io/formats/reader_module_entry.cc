// The exported entry points of libgravcal_formats.so (reader_module.h):
// compiled into the module only, beside the readers themselves.
#include "io/formats/file_format.h"
#include "io/formats/message_recording.h"
#include "io/formats/reader_module.h"

#ifndef GRAVCAL_VERSION
#error "GRAVCAL_VERSION must be defined by the build (CMakeLists.txt)"
#endif

extern "C" __attribute__((visibility("default"))) const char* gravcal_formats_version() {
  return GRAVCAL_VERSION;
}

extern "C" __attribute__((visibility("default"))) gravcal::internal::MessageRecording*
gravcal_formats_new_recording(int format) {
  using gravcal::internal::FileFormat;
  switch (static_cast<FileFormat>(format)) {
    case FileFormat::kRos1Bag:
      return gravcal::internal::NewRos1Bag().release();
    case FileFormat::kRosbag2Sqlite:
      return gravcal::internal::NewRosbag2Sqlite().release();
    case FileFormat::kMcap:
      return gravcal::internal::NewMcapFile().release();
    default:
      return nullptr;
  }
}
