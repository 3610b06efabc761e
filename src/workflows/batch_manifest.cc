#include "gravcal/workflows/batch_manifest.h"

#include <dirent.h>
#include <fnmatch.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <map>
#include <set>
#include <system_error>

#include "gravcal/io/files.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/io/recording.h"
#include "io/csv_table.h"

namespace gravcal {
namespace {

std::string Resolve(const std::string& folder, const std::string& path) {
  if (path.empty() || path[0] == '/' || folder.empty() || folder == ".") return path;
  return folder + "/" + path;
}

std::string FolderOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

}  // namespace

bool IsValidUnitId(const std::string& id, std::string* why) {
  if (id.empty()) {
    *why = "is empty";
    return false;
  }
  if (id.size() > 200) {
    *why = "is longer than 200 characters";
    return false;
  }
  if (id[0] == '.') {
    *why = "must not start with '.'";
    return false;
  }
  if (id == "summary") {
    *why = "is reserved for summary.csv and summary.json";
    return false;
  }
  for (char c : id) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '.' || c == '_' || c == '-';
    if (!ok) {
      *why = "may only hold letters, digits, '.', '_' and '-'";
      return false;
    }
  }
  return true;
}

bool ParseBatchManifest(std::string_view text, const std::string& name, const std::string& folder,
                        const Config& base, std::vector<BatchUnit>* units, std::string* error) {
  std::vector<CsvRecord> records;
  if (!ParseCsvRecords(text, name, &records, error)) return false;
  if (records.empty()) {
    *error = name + ": empty manifest: needs a header row with unit and path";
    return false;
  }
  const CsvRecord& header = records[0];
  int unit_column = -1;
  int path_column = -1;
  int attitudes_column = -1;
  std::set<std::string> seen;
  for (size_t i = 0; i < header.cells.size(); ++i) {
    const CsvCell& cell = header.cells[i];
    const std::string where = CsvWhere(name, header.line, cell.column);
    if (!seen.insert(cell.text).second) {
      *error = where + "column '" + cell.text + "' appears twice";
      return false;
    }
    if (cell.text == "unit") {
      unit_column = static_cast<int>(i);
    } else if (cell.text == "path") {
      path_column = static_cast<int>(i);
    } else if (cell.text == "attitudes") {
      attitudes_column = static_cast<int>(i);
    } else if (!IsConfigKey(cell.text)) {
      *error = where + "column '" + cell.text +
               "' is not unit, path, attitudes or a config key (gravcal help batch lists them)";
      return false;
    }
  }
  if (unit_column < 0 || path_column < 0) {
    *error = CsvWhere(name, header.line, 1) + "the header needs the columns unit and path";
    return false;
  }

  std::vector<BatchUnit> out;
  std::map<std::string, size_t> line_of_unit;
  for (size_t r = 1; r < records.size(); ++r) {
    const CsvRecord& record = records[r];
    if (record.cells.size() != header.cells.size()) {
      const size_t column =
          record.cells.size() > header.cells.size() ? record.cells[header.cells.size()].column : 1;
      *error = CsvWhere(name, record.line, column) + "has " + std::to_string(record.cells.size()) +
               " fields, the header " + std::to_string(header.cells.size());
      return false;
    }
    BatchUnit unit;
    const CsvCell& id = record.cells[unit_column];
    std::string why;
    if (!IsValidUnitId(id.text, &why)) {
      *error = CsvWhere(name, record.line, id.column) + "unit id '" + id.text + "' " + why;
      return false;
    }
    const auto [it, inserted] = line_of_unit.emplace(id.text, record.line);
    if (!inserted) {
      *error = CsvWhere(name, record.line, id.column) + "unit '" + id.text +
               "' is already on line " + std::to_string(it->second);
      return false;
    }
    unit.id = id.text;
    const CsvCell& path = record.cells[path_column];
    if (path.text.empty()) {
      *error = CsvWhere(name, record.line, path.column) + "unit '" + unit.id + "' has no path";
      return false;
    }
    unit.path = Resolve(folder, path.text);
    if (attitudes_column >= 0) {
      unit.attitudes_path = Resolve(folder, record.cells[attitudes_column].text);
    }
    Config config = base;
    for (size_t i = 0; i < record.cells.size(); ++i) {
      const int column = static_cast<int>(i);
      const CsvCell& cell = record.cells[i];
      if (column == unit_column || column == path_column || column == attitudes_column ||
          cell.text.empty()) {
        continue;
      }
      const std::string& key = header.cells[i].text;
      const std::string value = key == "gyro_path" ? Resolve(folder, cell.text) : cell.text;
      if (!SetConfigValue(key, value, &config, &why)) {
        *error = CsvWhere(name, record.line, cell.column) + why;
        return false;
      }
      unit.overrides.emplace_back(key, value);
    }
    if (!config.IsValid(&why)) {
      *error = CsvWhere(name, record.line, 1) + "unit '" + unit.id + "': " + why;
      return false;
    }
    out.push_back(std::move(unit));
  }
  if (out.empty()) {
    *error = name + ": the manifest lists no units";
    return false;
  }
  *units = std::move(out);
  return true;
}

bool ReadBatchManifest(const std::string& path, const Config& base, std::vector<BatchUnit>* units,
                       std::string* error) {
  std::string text;
  if (!ReadFileBytes(path, &text, error)) return false;
  return ParseBatchManifest(text, path, FolderOf(path), base, units, error);
}

bool UnitsFromDirectory(const std::string& folder, const std::string& pattern,
                        std::vector<BatchUnit>* units, std::string* error,
                        const std::vector<std::string>& exclude, std::vector<std::string>* hidden) {
  DIR* dir = opendir(folder.c_str());
  if (dir == nullptr) {
    *error = folder + ": cannot open the folder: " + std::generic_category().message(errno);
    return false;
  }
  std::vector<std::string> names;
  size_t skipped = 0;  // hidden names that match
  while (const dirent* entry = readdir(dir)) {
    const std::string file = entry->d_name;
    if (file == "." || file == ".." || fnmatch(pattern.c_str(), file.c_str(), 0) != 0) continue;
    if (std::find(exclude.begin(), exclude.end(), file) != exclude.end()) continue;
    if (file[0] == '.') {
      ++skipped;
      if (hidden != nullptr && !IsGravcalTemporaryName(file)) hidden->push_back(file);
      continue;
    }
    struct stat st;
    if (stat((folder + "/" + file).c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
      names.push_back(file);
    }
  }
  closedir(dir);
  std::sort(names.begin(), names.end());
  if (hidden != nullptr) std::sort(hidden->begin(), hidden->end());
  if (names.empty()) {
    *error = folder + ": no file matches '" + pattern + "'" +
             (skipped == 0 ? ""
                           : " (only hidden files do: hidden and AppleDouble '._' files are "
                             "never units)");
    return false;
  }
  std::vector<BatchUnit> out;
  std::map<std::string, std::string> file_of_unit;
  for (const std::string& file : names) {
    const size_t dot = file.find_last_of('.');
    BatchUnit unit;
    unit.id = dot == std::string::npos || dot == 0 ? file : file.substr(0, dot);
    unit.path = folder + "/" + file;
    std::string why;
    if (!IsValidUnitId(unit.id, &why)) {
      *error =
          unit.path + ": the unit id '" + unit.id + "' (the file name without extension) " + why;
      return false;
    }
    const auto [it, inserted] = file_of_unit.emplace(unit.id, file);
    if (!inserted) {
      *error = unit.path + ": unit id '" + unit.id + "' is also the id of " + it->second;
      return false;
    }
    out.push_back(std::move(unit));
  }
  *units = std::move(out);
  return true;
}

bool UnitsFromTopics(const std::string& path, std::vector<BatchUnit>* units, std::string* error) {
  std::vector<std::string> topics;
  if (!ListImuTopics(path, &topics, error)) return false;
  std::vector<BatchUnit> out;
  std::set<std::string> ids;
  for (const std::string& topic : topics) {
    if (topic.empty()) {
      *error = path + ": --topics all needs a bag or MCAP file; this is a text log";
      return false;
    }
    BatchUnit unit;
    unit.id = topic.substr(topic[0] == '/' ? 1 : 0);
    std::replace(unit.id.begin(), unit.id.end(), '/', '_');
    unit.path = path;
    unit.overrides = {{"topic", topic}};
    std::string why;
    if (!IsValidUnitId(unit.id, &why) || !ids.insert(unit.id).second) {
      *error = path + ": topic '" + topic + "' does not make a unit id: " +
               (why.empty() ? "another topic gives the same id" : why);
      return false;
    }
    out.push_back(std::move(unit));
  }
  *units = std::move(out);
  return true;
}

bool ParseShard(const std::string& text, Shard* shard, std::string* error) {
  const size_t slash = text.find('/');
  auto parse = [](const std::string& s, int* v) {
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) {
      return false;
    }
    *v = std::atoi(s.c_str());
    return true;
  };
  Shard s;
  if (slash == std::string::npos || !parse(text.substr(0, slash), &s.index) ||
      !parse(text.substr(slash + 1), &s.count) || s.index < 1 || s.index > s.count) {
    *error = "shard '" + text + "' must be K/N with 1 <= K <= N, e.g. 3/16";
    return false;
  }
  *shard = s;
  return true;
}

std::vector<size_t> ShardPositions(size_t units, const Shard& shard) {
  std::vector<size_t> positions;
  for (size_t i = static_cast<size_t>(shard.index - 1); i < units;
       i += static_cast<size_t>(shard.count)) {
    positions.push_back(i);
  }
  return positions;
}

}  // namespace gravcal
