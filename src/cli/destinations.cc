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

// The config and the gyroscope file it may name (input: gyro_path).
std::vector<Source> ConfigSources(const CommonArgs& args) {
  return {{args.config_path, "--config"}, {args.config.input.gyro_path, "gyro_path"}};
}

// `out` and `in` checked, `in` after the config's sources.
bool Check(const CommonArgs& args, const std::vector<Destination>& out,
           const std::vector<Source>& in, std::string* error) {
  std::vector<Source> sources = ConfigSources(args);
  sources.insert(sources.end(), in.begin(), in.end());
  return CheckDestinations(out, sources, error);
}

// The folder and its files `names`, under `flag`.
std::vector<Destination> FolderFiles(const std::string& folder, const char* flag,
                                     const std::vector<const char*>& names) {
  std::vector<Destination> out = {{folder, flag, false, true}};
  for (const char* name : names) out.push_back({In(folder, name), flag});
  return out;
}

}  // namespace

bool CheckCommandDestinations(const CommonArgs& args, std::string* error) {
  return Check(args, {}, {}, error);
}

bool CheckCommandDestinations(const CalibrateArgs& args, std::string* error) {
  std::vector<Destination> out = {
      {args.output, "--output", true}, {args.report, "--report"}, {args.history, "--history"}};
  if (!args.certificate.empty()) {
    out.push_back({args.certificate + ".json", "--certificate"});
    out.push_back({args.certificate + ".html", "--certificate"});
  }
  return Check(args, out,
               {{args.input, "--input"},
                {args.attitudes, "--attitudes"},
                {args.segments, "--segments"},
                {args.noise, "--noise"},
                {args.limits, "--limits"}},
               error);
}

bool CheckCommandDestinations(const ApplyArgs& args, std::string* error) {
  return Check(args, {{args.output, "--output", true}},
               {{args.input, "--input"}, {args.calibration, "--calibration"}}, error);
}

bool CheckCommandDestinations(const SimulateArgs& args, std::string* error) {
  return Check(args,
               FolderFiles(args.output_dir, "--output-dir",
                           {"raw.csv", "truth.json", "attitudes.csv", "segments.csv"}),
               {{args.plan, "--plan"}}, error);
}

bool CheckCommandDestinations(const PlanArgs& args, std::string* error) {
  // plan --verify's design may go to standard output.
  const bool verify = !args.verify_calibration.empty();
  return Check(args, {{args.output, "--output", verify}, {args.report, "--report"}},
               {{args.noise, "--noise"}, {args.verify_calibration, "--verify"}}, error);
}

bool CheckCommandDestinations(const BatchArgs& args, std::string* error) {
  // --input-dir may be the output folder: the batch tells its own files
  // apart (workflows/batch_folder.h).
  std::vector<Destination> out =
      FolderFiles(args.output_dir, "--output-dir", {"summary.csv", "summary.json"});
  out.push_back({args.report, "--report"});
  if (!args.limits.empty()) out.push_back({In(args.output_dir, "limits.csv"), "--output-dir"});
  std::vector<Source> in = {
      {args.manifest, "--manifest"}, {args.input, "--input"}, {args.limits, "--limits"}};
  for (const std::string& folder : args.positional) {
    in.insert(in.end(), {{folder, "shard folder"},
                         {In(folder, "summary.csv"), "shard summary"},
                         {In(folder, "summary.json"), "shard summary"}});
  }
  return Check(args, out, in, error);
}

bool CheckCommandDestinations(const LogReportArgs& args, std::string* error) {
  return Check(args,
               {{args.output, "--output"},
                {args.kalibr, "--kalibr"},
                {args.handheld, "--handheld"},
                {args.report, "--report"}},
               {{args.input, "--input"}}, error);
}

bool CheckCommandDestinations(const ExportArgs& args, std::string* error) {
  const bool c_target = args.to == ExportTarget::kC;
  return Check(args,
               c_target ? FolderFiles(args.output_dir, "--output-dir",
                                      {"gravcal_correct.h", "gravcal_correct.c"})
                        : std::vector<Destination>{{args.output, "--output", true}},
               {{args.calibration, "--calibration"}, {args.noise, "--noise"}}, error);
}

bool CheckCommandDestinations(const CompareArgs& args, std::string* error) {
  std::vector<Source> in = {{args.input, "--input"}};
  const char* names[] = {"first calibration", "second calibration"};
  for (size_t i = 0; i < args.positional.size() && i < 2; ++i) {
    in.push_back({args.positional[i], names[i]});
  }
  return Check(args, {{args.output, "--output", true}}, in, error);
}

bool CheckCommandDestinations(const VerifyArgs& args, std::string* error) {
  return Check(args, {{args.output, "--output", true}},
               {{args.calibration, "--calibration"}, {args.input, "--input"}}, error);
}

bool CheckCommandDestinations(const HistoryArgs& args, std::string* error) {
  return Check(args, {{args.output, "--output", true}, {args.report, "--report"}}, {}, error);
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
