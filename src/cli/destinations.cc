// Every command's destinations and sources (io/files.h, the destination
// contract), checked in main before the command does any work.
#include <cstdio>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "gravcal/io/calibration_export.h"
#include "gravcal/io/files.h"

namespace gravcal {
namespace cli {
namespace {

// "d/name" for a file of an output folder.
std::string In(const std::string& folder, const char* name) {
  if (folder.empty()) return "";
  return folder + (folder.back() == '/' ? "" : "/") + name;
}

}  // namespace

bool CheckCommandDestinations(const std::string& command, const CommandArgs& args,
                              std::string* error) {
  std::vector<Destination> out;
  std::vector<Source> in = {{args.config_path, "--config"}};
  auto folder_files = [&](const char* flag, const std::vector<const char*>& names) {
    out.push_back({args.output_dir, flag, false, true});
    for (const char* name : names) out.push_back({In(args.output_dir, name), flag});
  };
  if (command == "calibrate") {
    out = {{args.output, "--output", true}, {args.report, "--report"}, {args.history, "--history"}};
    in.insert(in.end(), {{args.input, "--input"},
                         {args.attitudes, "--attitudes"},
                         {args.segments, "--segments"},
                         {args.noise, "--noise"}});
  } else if (command == "apply") {
    out = {{args.output, "--output", true}};
    in.insert(in.end(), {{args.input, "--input"}, {args.calibration, "--calibration"}});
  } else if (command == "simulate") {
    folder_files("--output-dir", {"raw.csv", "truth.json", "attitudes.csv", "segments.csv"});
    in.push_back({args.plan, "--plan"});
  } else if (command == "plan") {
    out = {{args.output, "--output"}, {args.report, "--report"}};
    in.push_back({args.noise, "--noise"});
  } else if (command == "batch") {
    // --input-dir may be the output folder: the batch tells its own files
    // apart (batch_command.cc).
    folder_files("--output-dir", {"summary.csv", "summary.json"});
    out.push_back({args.report, "--report"});
    in.insert(in.end(), {{args.manifest, "--manifest"}, {args.input, "--input"}});
  } else if (command == "merge-summaries") {
    folder_files("--output-dir", {"summary.csv", "summary.json"});
    for (const std::string& folder : args.positional) {
      in.insert(in.end(), {{folder, "shard folder"},
                           {In(folder, "summary.csv"), "shard summary"},
                           {In(folder, "summary.json"), "shard summary"}});
    }
  } else if (command == "discover") {
    out = {{args.output, "--output"}, {args.report, "--report"}};
    in.push_back({args.input, "--input"});
  } else if (command == "noise") {
    out = {{args.output, "--output"},
           {args.kalibr, "--kalibr"},
           {args.handheld, "--handheld"},
           {args.report, "--report"}};
    in.push_back({args.input, "--input"});
  } else if (command == "export") {
    ExportTarget target;
    if (FromString(args.to, &target) && target == ExportTarget::kC) {
      folder_files("--output-dir", {"gravcal_correct.h", "gravcal_correct.c"});
    } else {
      out = {{args.output, "--output", true}};
    }
    in.insert(in.end(), {{args.calibration, "--calibration"}, {args.noise, "--noise"}});
  }
  return CheckDestinations(out, in, error);
}

bool WriteOutput(const std::string& path, const std::string& text, std::string* error) {
  if (path != "-") return WriteFileAtomically(path, text, error);
  if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0) {
    *error = "standard output: cannot write";
    return false;
  }
  return true;
}

}  // namespace cli
}  // namespace gravcal
