// gravcal/workflows/batch_manifest.h: the units of a batch, from a manifest CSV or from
// the files in a folder, and the deterministic split into shards.
//
// Manifest CSV (docs/data_contract.md, "Batch manifest"): a header row, one unit per
// row. Required columns `unit` (the id: letters, digits, '.', '_', '-', not
// starting with '.', not "summary"; unique) and `path` (the raw log). Optional
// `gyro_path` (second file with the gyroscope, see log_reader.h) and
// `attitudes` (the method's attitudes CSV). Paths are relative to the
// manifest's folder unless absolute. Every other column is a config key whose
// value overrides the base config for that unit (`gravity`, `latitude`,
// `parameterization`, ...); an empty cell keeps the base value. Fields may be
// quoted ("[+z, -z]"); '#' lines and blank lines are skipped. Errors name the
// file, line and column and nothing is read past them.
#ifndef GRAVCAL_WORKFLOWS_BATCH_MANIFEST_H_
#define GRAVCAL_WORKFLOWS_BATCH_MANIFEST_H_

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/config.h"

namespace gravcal {

// False with the reason when `id` cannot be a unit id (it is used as a file
// name: results/<id>.json).
bool IsValidUnitId(const std::string& id, std::string* why);

// Reads a manifest file. Every row's overrides are applied to `base` and the
// result checked, so a bad value is reported here with its line and column.
bool ReadBatchManifest(const std::string& path, const Config& base, std::vector<BatchUnit>* units,
                       std::string* error);

// Same on text in memory: `name` is used in messages, relative paths are
// resolved against `folder`.
bool ParseBatchManifest(std::string_view text, const std::string& name, const std::string& folder,
                        const Config& base, std::vector<BatchUnit>* units, std::string* error);

// Every regular file in `folder` whose name matches the shell `pattern`
// ("*.csv") is a unit with id = the file name without its last extension,
// in sorted order of file names (the same on every machine). Hidden files
// (".name", also AppleDouble "._name" files and gravcal's temporaries) are
// never units: their names go to *hidden when given. Names in `exclude`
// (a batch's own files in its input folder) are left out.
bool UnitsFromDirectory(const std::string& folder, const std::string& pattern,
                        std::vector<BatchUnit>* units, std::string* error,
                        const std::vector<std::string>& exclude = {},
                        std::vector<std::string>* hidden = nullptr);

// One unit per sensor_msgs/Imu topic of the bag or MCAP file at `path`
// (batch --topics all): id = the topic without its leading '/', other '/'
// as '_' ("/imu0" -> "imu0"), with the override topic = the topic's name.
bool UnitsFromTopics(const std::string& path, std::vector<BatchUnit>* units, std::string* error);

// Shard K of N: the units whose 0-based position i in the whole list has
// i mod N == K - 1. Deterministic, balanced to one unit, and independent of
// the files' contents.
struct Shard {
  int index = 1;
  int count = 1;
};

// Parses "K/N" with 1 <= K <= N.
bool ParseShard(const std::string& text, Shard* shard, std::string* error);

// Positions (0-based, increasing) of the units of `shard` among `units`.
std::vector<size_t> ShardPositions(size_t units, const Shard& shard);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_BATCH_MANIFEST_H_
