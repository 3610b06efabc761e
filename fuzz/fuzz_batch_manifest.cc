// Fuzz target: the batch manifest (ParseBatchManifest). Units read must have
// valid, unique ids and a path.
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "fuzz_check.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/batch_manifest.h"

using gravcal::fuzz::Require;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<gravcal::BatchUnit> units;
  std::string error;
  const bool ok =
      gravcal::ParseBatchManifest(text, "fuzz.csv", "/data", gravcal::Config(), &units, &error);
  gravcal::fuzz::RequireOutcome(ok, error);
  if (ok) {
    std::set<std::string> ids;
    for (const gravcal::BatchUnit& u : units) {
      std::string why;
      Require(gravcal::IsValidUnitId(u.id, &why), "invalid unit id accepted");
      Require(ids.insert(u.id).second, "unit id twice");
      Require(!u.path.empty(), "unit without a path");
    }
  }
  return 0;
}
