// cli/read_long_log.h (private): the log of a command that may be long.
#ifndef GRAVCAL_SRC_CLI_READ_LONG_LOG_H_
#define GRAVCAL_SRC_CLI_READ_LONG_LOG_H_

#include <string>

#include "gravcal/core/imu_log.h"
#include "gravcal/io/log_reader.h"

namespace gravcal {
namespace cli {

// Reads a log in bounded memory (io/long_log.h, the input key
// max_log_entries; commands.cc), saying on stderr when it was read as block
// means.
bool ReadLongLog(const std::string& path, const LogReaderOptions& input, ImuLog* log,
                 std::string* error);

}  // namespace cli
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CLI_READ_LONG_LOG_H_
