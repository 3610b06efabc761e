// The layering rule of docs/architecture.md, checked on the source tree:
// every file under include/gravcal/<wing>/ and src/<wing>/ includes only
// headers of its own wing or of lower wings, public headers include no
// private header, no public header but the residuals (and their umbrella
// gravcal/ceres.h) includes Ceres or glog, every source file lives in a
// known wing, and no .cc is over 600 lines (a room holds one concept, issue
// 34). A violation names the file, the line and the include.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "test_util.h"

namespace gravcal {
namespace {

namespace fs = std::filesystem;

// Rank of each wing, bottom to top. Wings of equal rank are siblings and may
// not include each other.
const std::map<std::string, int>& WingRanks() {
  static const std::map<std::string, int> ranks = {
      {"util", 0}, {"core", 1},       {"detection", 2}, {"residuals", 2}, {"estimation", 3},
      {"io", 4},   {"simulation", 5}, {"methods", 6},   {"workflows", 7}, {"cli", 8},
  };
  return ranks;
}

struct Include {
  std::string wing;  // empty when the include is not a gravcal header
  bool is_public = false;
};

// The umbrella headers directly in include/gravcal/ and the wing they
// belong to: gravcal.h (the core: log, model, methods, read/write) at the
// rank of methods, ceres.h (the residuals) at the residuals'.
const std::map<std::string, std::string>& Umbrellas() {
  static const std::map<std::string, std::string> umbrellas = {
      {"gravcal.h", "methods"},
      {"ceres.h", "residuals"},
  };
  return umbrellas;
}

// "gravcal/core/x.h" -> public core; "util/x.h" -> private util; an
// umbrella "gravcal/gravcal.h" -> its wing.
Include Classify(const std::string& path) {
  Include inc;
  for (const auto& [name, wing] : Umbrellas()) {
    if (path == "gravcal/" + name) {
      inc.wing = wing;
      inc.is_public = true;
      return inc;
    }
  }
  const size_t slash = path.find('/');
  if (slash == std::string::npos) return inc;
  std::string first = path.substr(0, slash);
  if (first == "gravcal") {
    inc.is_public = true;
    const std::string rest = path.substr(slash + 1);
    const size_t s2 = rest.find('/');
    first = s2 == std::string::npos ? "" : rest.substr(0, s2);
  }
  if (WingRanks().count(first) != 0) inc.wing = first;
  return inc;
}

// The longest a .cc may be.
constexpr int kMaxSourceLines = 600;

// Violations in the tree at `root` (which has include/gravcal and src).
std::vector<std::string> CheckLayering(const fs::path& root) {
  std::vector<std::string> violations;
  const std::regex include_re("^\\s*#\\s*include\\s+\"([^\"]+)\"");
  const std::regex solver_re("^\\s*#\\s*include\\s+<((ceres|glog)/[^>]+)>");
  struct Tree {
    fs::path dir;
    bool is_public;
  };
  for (const Tree& tree : {Tree{root / "include" / "gravcal", true}, Tree{root / "src", false}}) {
    if (!fs::exists(tree.dir)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(tree.dir)) {
      if (!entry.is_regular_file()) continue;
      const std::string ext = entry.path().extension().string();
      if (ext != ".h" && ext != ".cc") continue;
      const fs::path rel = fs::relative(entry.path(), tree.dir);
      const std::string shown = fs::relative(entry.path(), root).generic_string();
      const bool umbrella = tree.is_public && Umbrellas().count(rel.generic_string()) != 0;
      const std::string wing =
          umbrella ? Umbrellas().at(rel.generic_string()) : rel.begin()->string();
      if (!umbrella &&
          (WingRanks().count(wing) == 0 || std::distance(rel.begin(), rel.end()) < 2)) {
        violations.push_back(shown + ": not inside a wing folder");
        continue;
      }
      const int rank = WingRanks().at(wing);
      std::ifstream in(entry.path());
      std::string line;
      int line_number = 0;
      while (std::getline(in, line)) {
        ++line_number;
        if (wing != "cli" && line.find("gflags/gflags.h") != std::string::npos) {
          violations.push_back(shown + ":" + std::to_string(line_number) +
                               ": gflags outside src/cli");
        }
        std::smatch m;
        if (tree.is_public && wing != "residuals" && std::regex_search(line, m, solver_re)) {
          violations.push_back(shown + ":" + std::to_string(line_number) +
                               ": public header outside residuals/ includes <" + m[1].str() + ">");
        }
        if (!std::regex_search(line, m, include_re)) continue;
        const std::string target = m[1];
        const Include inc = Classify(target);
        const std::string where = shown + ":" + std::to_string(line_number) + ": ";
        if (tree.is_public && !inc.is_public) {
          violations.push_back(where + "public header includes non-public \"" + target + "\"");
          continue;
        }
        if (inc.wing.empty() || inc.wing == wing) continue;
        const int target_rank = WingRanks().at(inc.wing);
        if (target_rank >= rank) {
          violations.push_back(where + "wing '" + wing + "' includes \"" + target + "\" of wing '" +
                               inc.wing + "' (" +
                               (target_rank == rank ? "a sibling" : "a higher wing") + ")");
        }
      }
      if (ext == ".cc" && line_number > kMaxSourceLines) {
        violations.push_back(shown + ": " + std::to_string(line_number) + " lines (at most " +
                             std::to_string(kMaxSourceLines) + ": split it by concept)");
      }
    }
  }
  return violations;
}

std::string Join(const std::vector<std::string>& lines) {
  std::string s;
  for (const std::string& l : lines) s += l + "\n";
  return s;
}

TEST(Layering, SourceTreeIncludesOnlyLowerWings) {
  const fs::path root = testing_util::SourceDir();
  ASSERT_TRUE(fs::exists(root / "src" / "core")) << root;
  const std::vector<std::string> violations = CheckLayering(root);
  EXPECT_TRUE(violations.empty()) << Join(violations);
}

// The checker itself: a planted upward include, a sibling include, a public
// header reaching a private one and a file outside the wings are each named.
TEST(Layering, PlantedViolationsAreNamed) {
  const fs::path root =
      fs::path(::testing::TempDir()) / ("gravcal_layering_" + std::to_string(::getpid()));
  fs::remove_all(root);
  auto write = [&](const std::string& rel, const std::string& text) {
    fs::create_directories((root / rel).parent_path());
    std::ofstream(root / rel) << text;
  };
  write("include/gravcal/core/a.h", "#include \"gravcal/methods/b.h\"\n");
  write("include/gravcal/methods/b.h", "#include \"gravcal/core/a.h\"\n");
  write("include/gravcal/detection/c.h", "#include <vector>\n#include \"gravcal/residuals/d.h\"\n");
  write("include/gravcal/residuals/d.h", "#include \"util/so3.h\"\n");
  write("src/estimation/e.cc", "#include \"gravcal/estimation/e.h\"\n#include \"methods/x.h\"\n");
  write("src/util/ok.h", "#include <cmath>\n");
  write("src/loose.cc", "int x;\n");
  write("src/workflows/flags.cc", "#include <gflags/gflags.h>\n");
  write("include/gravcal/estimation/f.h", "#include <ceres/ceres.h>\n");
  write("include/gravcal/residuals/ok.h", "#include <ceres/ceres.h>\n");
  write("include/gravcal/gravcal.h", "#include <glog/logging.h>\n#include \"gravcal/core/a.h\"\n");
  write("include/gravcal/ceres.h", "#include \"gravcal/residuals/d.h\"\n");
  write("src/core/long.cc", std::string(601, '\n'));
  write("src/core/just.cc", std::string(600, '\n'));
  const std::vector<std::string> v = CheckLayering(root);
  const std::string all = Join(v);
  EXPECT_EQ(v.size(), 9u) << all;
  EXPECT_NE(all.find("src/core/long.cc: 601 lines (at most 600"), std::string::npos) << all;
  EXPECT_NE(all.find("include/gravcal/core/a.h:1: wing 'core' includes \"gravcal/methods/b.h\""),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("include/gravcal/detection/c.h:2: wing 'detection' includes "
                     "\"gravcal/residuals/d.h\" of wing 'residuals' (a sibling)"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("include/gravcal/residuals/d.h:1: public header includes non-public"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("src/estimation/e.cc:2: wing 'estimation' includes \"methods/x.h\""),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("src/loose.cc: not inside a wing folder"), std::string::npos) << all;
  EXPECT_NE(all.find("src/workflows/flags.cc:1: gflags outside src/cli"), std::string::npos) << all;
  EXPECT_NE(all.find("include/gravcal/estimation/f.h:1: public header outside residuals/ includes "
                     "<ceres/ceres.h>"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("include/gravcal/gravcal.h:1: public header outside residuals/ includes "
                     "<glog/logging.h>"),
            std::string::npos)
      << all;
  fs::remove_all(root);
}

}  // namespace
}  // namespace gravcal
