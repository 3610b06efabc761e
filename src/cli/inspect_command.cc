// gravcal inspect: what a log file holds (format, topics and their types,
// message counts, rates, time span, gaps), so that a user can see why a
// file is refused or which --topic to give.
#include <cstdio>
#include <string>

#include "cli/commands.h"
#include "gravcal/io/recording.h"

namespace gravcal {
namespace cli {

int RunInspect(const InspectArgs& args) {
  if (args.input.empty()) return Fail("inspect needs --input");
  RecordingSummary summary;
  std::string error;
  if (!InspectRecording(args.input, args.config.input, &summary, &error)) return Fail(error);
  std::printf("file:   %s\nformat: %s\n", args.input.c_str(), summary.format.c_str());
  int imu_topics = 0;
  for (const TopicSummary& t : summary.topics) {
    imu_topics += t.imu ? 1 : 0;
    std::printf("\n%s  [%s]%s\n", t.name.empty() ? "(the log)" : t.name.c_str(), t.type.c_str(),
                t.imu ? "" : "  (not read by gravcal)");
    std::printf("  messages %lld", static_cast<long long>(t.messages));
    if (t.messages > 0) {
      std::printf(", time %.6f .. %.6f s (span %.6g s)", t.first_s, t.last_s, t.last_s - t.first_s);
    }
    if (t.rate_hz > 0.0) std::printf(", %.6g Hz", t.rate_hz);
    std::printf("\n");
    if (t.imu && t.messages > 1) {
      std::printf("  median interval %.6g s, longest %.6g s, %lld gaps (intervals > 2x median)\n",
                  t.median_interval_s, t.longest_interval_s, static_cast<long long>(t.gaps));
    }
  }
  if (summary.topics.size() > 1 || (!summary.topics.empty() && !summary.topics[0].name.empty())) {
    std::printf("\n%d sensor_msgs/Imu topic%s%s\n", imu_topics, imu_topics == 1 ? "" : "s",
                imu_topics > 1    ? ": give one with --topic"
                : imu_topics == 0 ? ": nothing gravcal can read"
                                  : "");
  }
  return 0;
}

}  // namespace cli
}  // namespace gravcal
