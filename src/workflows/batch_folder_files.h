// workflows/batch_folder_files.h (private): the file checks of a batch
// written to a folder (batch_folder.h): folders, and which files of the
// batch are whose.
#ifndef GRAVCAL_SRC_WORKFLOWS_BATCH_FOLDER_FILES_H_
#define GRAVCAL_SRC_WORKFLOWS_BATCH_FOLDER_FILES_H_

#include <string>
#include <vector>

#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/fleet_summary.h"

namespace gravcal {
namespace internal {

// mkdir -p; false with the folder that cannot be made.
bool MakeFolders(const std::string& path, std::string* error);

bool FileExists(const std::string& path);

// The batch's own files (summary.csv, summary.json of output_dir, the
// report) that are in its input folder (the input folder equal to the
// output folder, or the report written there), to leave out of the units.
// A file there that is not what a batch writes is a unit log the batch
// would overwrite: refused.
bool OwnFilesInInput(const std::string& input_dir, const std::string& output_dir,
                     const std::string& report, std::vector<std::string>* own, std::string* error);

// No output of the batch (summary.csv, summary.json, the report, each
// unit's result and state file) is the log or side file of one of its
// units: false naming both.
bool CheckUnitsAgainstOutputs(const std::vector<BatchUnit>& units, const std::string& output_dir,
                              const std::string& report, std::string* error);

// The fleet statistics of `rows`, written as folder/summary.csv and
// folder/summary.json.
bool WriteSummaryFiles(const std::string& folder, const std::vector<SummaryRow>& rows,
                       const FleetInfo& info, const FleetOptions& fleet,
                       FleetStatistics* statistics, std::string* error);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_BATCH_FOLDER_FILES_H_
