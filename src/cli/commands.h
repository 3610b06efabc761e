// The gravcal command-line tool's commands. Each returns the process exit
// code: 0 success, 1 bad input or configuration, 2 the calibration failed.
#ifndef GRAVCAL_SRC_CLI_COMMANDS_H_
#define GRAVCAL_SRC_CLI_COMMANDS_H_

#include <string>

#include "gravcal/config.h"

namespace gravcal {
namespace cli {

struct CommandArgs {
  Config config;
  std::string input;
  std::string output;
  std::string output_dir;
  std::string calibration;
  std::string config_path;
  // discover: the HTML report to write (optional).
  std::string report;
  uint64_t seed = 1;
};

int RunDemo(const CommandArgs& args);
int RunCalibrate(const CommandArgs& args);
int RunApply(const CommandArgs& args);
int RunSimulate(const CommandArgs& args);
int RunDiscover(const CommandArgs& args);

// Prints "gravcal: error: <message>" on stderr and returns `code`.
int Fail(const std::string& message, int code = 1);

}  // namespace cli
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CLI_COMMANDS_H_
