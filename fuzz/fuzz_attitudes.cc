// Fuzz target: the fixture attitudes CSV (ReadFixtureAttitudes). Rows read
// must be finite where the contract says so and have positive std.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_check.h"
#include "gravcal/io/attitude_fixture.h"

using gravcal::fuzz::Require;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = gravcal::fuzz::WriteScratch("_attitudes.csv", data, size);
  std::vector<gravcal::FixtureAttitude> rows;
  std::string error;
  const bool ok = gravcal::ReadFixtureAttitudes(path, &rows, &error);
  gravcal::fuzz::RequireOutcome(ok, error);
  if (ok) {
    for (const gravcal::FixtureAttitude& r : rows) {
      Require(std::isfinite(r.roll_deg) && std::isfinite(r.pitch_deg), "non-finite attitude");
      Require(r.roll_std_deg > 0 && r.pitch_std_deg > 0, "std not positive");
    }
  }
  return 0;
}
