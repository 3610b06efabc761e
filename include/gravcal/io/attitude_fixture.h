// gravcal/io/attitude_fixture.h: the attitudes file of the known-attitude
// method (`--attitudes fixture.csv`): one row per static position, the
// roll and pitch a fixture or an external inclinometer gives, with their
// uncertainty.
//
// CSV with a header row; lines starting with '#' and blank lines are
// skipped. Columns (any order):
//   position            0-based index of the detected static position, or
//   t_begin, t_end      a time window (s, log time) containing the position;
//   roll_deg, pitch_deg the attitude, degrees (roll -180..180, pitch -90..90;
//                       the convention of static_alignment.h: the unit at
//                       rest reads g (-sin p, sin r cos p, cos r cos p));
//   roll_std_deg, pitch_std_deg  their standard deviations, degrees (> 0);
//   heading_deg, heading_std_deg optional; gravity does not depend on
//                       heading, so it is checked but not used.
// Every detected static position needs exactly one row, and every row must
// match one position; errors name the file and line.
#ifndef GRAVCAL_IO_ATTITUDE_FIXTURE_H_
#define GRAVCAL_IO_ATTITUDE_FIXTURE_H_

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "gravcal/core/position.h"

namespace gravcal {

// The smallest standard deviation a fixture row may claim, degrees.
constexpr double kMinFixtureStdDeg = 0.001;

struct FixtureAttitude {
  // Line in the file (1-based), for messages.
  int line = 0;
  // Static position index, or -1 when the row gives a time window.
  int position = -1;
  double t_begin = NAN;
  double t_end = NAN;
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double roll_std_deg = 0.0;
  double pitch_std_deg = 0.0;
  double heading_deg = NAN;
  double heading_std_deg = NAN;
};

// Reads and checks the file. Errors: "<path>:<line>: <what>" (missing
// column, not a number, NaN, out of range, non-positive std, t_end <=
// t_begin, duplicate position).
bool ReadFixtureAttitudes(const std::string& path, std::vector<FixtureAttitude>* rows,
                          std::string* error);

// rows[row_of_position[k]] is the attitude of static position k. Errors name
// the file (and the line of a row that matches no position or several, or
// the position that has no row).
bool MatchFixtureAttitudes(const std::vector<FixtureAttitude>& rows,
                           const std::vector<StaticInterval>& intervals, const std::string& path,
                           std::vector<int>* row_of_position, std::string* error);

// The file text for rows (time windows when t_begin is finite, else
// position indices).
std::string FixtureAttitudesToCsv(const std::vector<FixtureAttitude>& rows);

}  // namespace gravcal

#endif  // GRAVCAL_IO_ATTITUDE_FIXTURE_H_
