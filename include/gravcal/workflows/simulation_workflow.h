// gravcal/workflows/simulation_workflow.h: a simulated session made from a
// configuration, as `gravcal simulate` makes it, with the text of each file
// it writes. The command-line tool and the Python package both call
// SimulateFromConfig, so a seed gives the same files from either.
//
// The config chooses the simulator: sim_motion empty = the multi-position
// scheme of the sim_* keys (simulation/simulator.h), else the motion
// profile it names (simulation/handheld_simulator.h; rate_table also gives
// the constant-rate segments). A plan from `gravcal plan` replaces the
// scheme by its poses.
#ifndef GRAVCAL_WORKFLOWS_SIMULATION_WORKFLOW_H_
#define GRAVCAL_WORKFLOWS_SIMULATION_WORKFLOW_H_

#include <cstdint>
#include <string>
#include <vector>

#include "gravcal/core/rate_table_segment.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"

namespace gravcal {

struct SimulationRequest {
  // plan.json from `gravcal plan`: its poses, in order, each its own hold,
  // replace sim_scheme, with no still period before the first. Empty = none.
  std::string plan_path;
  uint64_t seed = 1;
};

// The session and the files `gravcal simulate` writes besides raw.csv
// (which is WriteImuLogCsv of session.log).
struct SimulationFiles {
  // The raw log and the truth.
  SimulatedSession session;
  // The simulator options used (the config's, with the plan's poses).
  SimulatorOptions options;
  // sim_motion rate_table: the constant-rate segments; else empty.
  std::vector<RateTableSegment> segments;
  // truth.json.
  std::string truth_json;
  // attitudes.csv: what a fixture would say about each pose (the true
  // attitudes plus sim_fixture_noise).
  std::string attitudes_csv;
  // segments.csv; empty when there are no segments.
  std::string segments_csv;
};

// Deterministic for a given (config, request). False with a one-line *error
// on an invalid config, an unreadable plan, or options the simulator
// refuses; *files is then unspecified.
bool SimulateFromConfig(const Config& config, const SimulationRequest& request,
                        SimulationFiles* files, std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_SIMULATION_WORKFLOW_H_
