// The data-driven bad-input suite (docs/bad-input-suite.md): every directory under
// tests/bad_input/ is one case, a run file (run.toml, optional) and expect.toml saying what the
// real `mresim` command must do with it: the exit status, a substring of the one-line error,
// and (for invalid input, status 2) that nothing was written. One generic driver runs them all.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../support/child_process.hpp"
#include "../support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using mresim::testing::read_text;
using mresim::testing::TempDir;

const fs::path kCasesDir = fs::path(MRESIM_SOURCE_DIR) / "tests" / "bad_input";
const std::vector<std::string> kDefaultArgs = {"run", "{run}", "--out", "{out}", "--no-plot"};
constexpr auto kTimeout = std::chrono::seconds(60);
// CLI11's hint after a command-line error; the only line allowed after the error line.
const std::string kUsageHint = "Run 'mresim --help' for usage.\n";

struct Case {
  std::string name;  // the directory name
  fs::path dir;
  std::vector<std::string> args = kDefaultArgs;
  int status = 2;
  std::string message;
  std::string absent;   // non-empty: a substring stderr must not contain
  std::string pending;  // non-empty: a known defect being fixed; the case is skipped
  std::string problem;  // non-empty: expect.toml itself is broken; the case fails
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

// Reads dir/expect.toml; a mistake in it (unknown key, wrong type) makes the case fail, so a
// misspelt expectation can never silently weaken a case.
Case load_case(const fs::path& dir) {
  Case c;
  c.name = dir.filename().string();
  c.dir = dir;
  toml::table t;
  try {
    t = toml::parse_file((dir / "expect.toml").string());
  } catch (const toml::parse_error& e) {
    c.problem = std::string("expect.toml: ") + std::string(e.description());
    return c;
  }
  static const std::set<std::string> kKeys = {"args",   "status",  "message",
                                              "absent", "pending", "note"};
  for (const auto& [key, value] : t) {
    if (!kKeys.contains(std::string(key.str())))
      c.problem += "unknown key '" + std::string(key.str()) + "'; ";
  }
  if (const auto* args = t["args"].as_array()) {
    c.args.clear();
    for (const auto& a : *args) {
      if (!a.is_string()) c.problem += "args: expected strings; ";
      c.args.push_back(a.value_or(std::string()));
    }
  }
  if (t.contains("status") && !t["status"].is_integer())
    c.problem += "status: expected an integer; ";
  c.status = static_cast<int>(t["status"].value_or(std::int64_t{2}));
  c.message = t["message"].value_or(std::string());
  if (c.message.empty()) c.problem += "message: required, a non-empty string; ";
  if (t.contains("absent") && !t["absent"].is_string()) c.problem += "absent: expected a string; ";
  c.absent = t["absent"].value_or(std::string());
  if (t.contains("pending") && !t["pending"].is_string())
    c.problem += "pending: expected a reason; ";
  c.pending = t["pending"].value_or(std::string());
  return c;
}

// Every case directory, sorted by name. Called while the tests are registered.
std::vector<Case> all_cases() {
  std::vector<Case> cases;
  if (!fs::is_directory(kCasesDir)) return cases;
  for (const auto& entry : fs::directory_iterator(kCasesDir)) {
    if (entry.is_directory()) cases.push_back(load_case(entry.path()));
  }
  std::sort(cases.begin(), cases.end(),
            [](const Case& a, const Case& b) { return a.name < b.name; });
  return cases;
}

// Relative path -> content of every regular file under `root` (directories as "<dir>/").
std::map<std::string, std::string> snapshot(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    const std::string rel = fs::relative(e.path(), root).string();
    files[e.is_directory() ? rel + "/" : rel] = e.is_regular_file() ? read_text(e.path()) : "";
  }
  return files;
}

// The case's files (all but expect.toml) copied into `work`.
void stage(const Case& c, const fs::path& work) {
  for (const auto& e : fs::directory_iterator(c.dir)) {
    if (e.path().filename() == "expect.toml") continue;
    fs::copy(e.path(), work / e.path().filename(), fs::copy_options::recursive);
  }
}

struct Outcome {
  int status = -1;  // exit status, or -1 when killed by a signal
  int signal = 0;
  bool hang = false;
  std::string out;
  std::string err;
};

// Runs `mresim args...` in `work` with stdin from /dev/null, killing it after kTimeout.
Outcome run_mresim(const fs::path& work, const std::vector<std::string>& args) {
  const TempDir capture;
  const std::string out_file = (capture / "stdout").string();
  const std::string err_file = (capture / "stderr").string();
  const pid_t pid = mresim::testing::start_child(MRESIM_CLI_PATH, args, work, out_file, err_file);
  Outcome result;
  if (pid < 0) return result;
  const auto deadline = std::chrono::steady_clock::now() + kTimeout;
  int raw = 0;
  while (::waitpid(pid, &raw, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      result.hang = true;
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &raw, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (WIFEXITED(raw)) result.status = WEXITSTATUS(raw);
  if (WIFSIGNALED(raw)) result.signal = WTERMSIG(raw);
  result.out = read_text(out_file);
  result.err = read_text(err_file);
  return result;
}

std::string substitute(std::string word) {
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"{run}", "run.toml"},
                                 std::pair<std::string, std::string>{"{out}", "out"}}) {
    for (auto at = word.find(from); at != std::string::npos; at = word.find(from))
      word.replace(at, from.size(), to);
  }
  return word;
}

// The error must be one line "mresim: error: <what>", optionally followed by CLI11's usage hint,
// and nothing else on stderr.
void expect_one_error_line(const std::string& err) {
  const std::string prefix = "mresim: error: ";
  EXPECT_EQ(err.rfind(prefix, 0), 0U) << "stderr does not start with '" << prefix << "':\n" << err;
  const auto end = err.find('\n');
  ASSERT_NE(end, std::string::npos) << "the error line is not terminated:\n" << err;
  const std::string rest = err.substr(end + 1);
  EXPECT_TRUE(rest.empty() || rest == kUsageHint) << "more than the error line on stderr:\n" << err;
}

// The names that are new, gone or changed in `after` compared with `before`.
std::string differences(const std::map<std::string, std::string>& before,
                        const std::map<std::string, std::string>& after) {
  std::string names;
  for (const auto& [name, content] : after) {
    const auto it = before.find(name);
    if (it == before.end())
      names += " created " + name + ";";
    else if (it->second != content)
      names += " changed " + name + ";";
  }
  for (const auto& [name, content] : before) {
    if (!after.contains(name)) names += " removed " + name + ";";
  }
  return names;
}

// Invalid input: the working directory is exactly as staged, no `out`, no `out.partial-*`.
void expect_nothing_written(const fs::path& work,
                            const std::map<std::string, std::string>& before) {
  EXPECT_FALSE(fs::exists(work / "out")) << "the output directory was created";
  for (const auto& e : fs::directory_iterator(work)) {
    const std::string name = e.path().filename().string();
    EXPECT_NE(name.rfind("out.partial-", 0), 0U) << "a staging directory was left: " << name;
  }
  EXPECT_EQ(differences(before, snapshot(work)), "") << "the working directory was touched";
}

class BadInputCase : public ::testing::TestWithParam<Case> {};

TEST_P(BadInputCase, ExitsWithTheExpectedStatusAndMessage) {
  const Case& c = GetParam();
  ASSERT_TRUE(c.problem.empty()) << c.dir << "/expect.toml: " << c.problem;
  if (!c.pending.empty() && std::getenv("MRESIM_BAD_INPUT_PENDING") == nullptr) {
    GTEST_SKIP() << "pending: " << c.pending;
  }
  const TempDir work;
  stage(c, work.path());
  const auto before = snapshot(work.path());
  std::vector<std::string> args;
  std::transform(c.args.begin(), c.args.end(), std::back_inserter(args), substitute);

  const Outcome r = run_mresim(work.path(), args);
  ASSERT_FALSE(r.hang) << "hang: still running after " << kTimeout.count() << " s";
  ASSERT_EQ(r.signal, 0) << "killed by signal " << r.signal << "; stderr:\n" << r.err;
  EXPECT_EQ(r.status, c.status) << "stderr:\n" << r.err;
  EXPECT_NE(r.err.find(c.message), std::string::npos) << "stderr lacks '" << c.message << "':\n"
                                                      << r.err;
  if (!c.absent.empty()) {
    EXPECT_EQ(r.err.find(c.absent), std::string::npos) << "stderr contains '" << c.absent << "':\n"
                                                       << r.err;
  }
  if (c.status == 2) {
    EXPECT_EQ(r.out, "") << "stdout should be empty";
    expect_one_error_line(r.err);
    expect_nothing_written(work.path(), before);
  }
}

INSTANTIATE_TEST_SUITE_P(BadInput, BadInputCase, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           std::string name = info.param.name;
                           for (char& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });

// The run types `mresim types` lists, first word of each line.
std::vector<std::string> run_types() {
  const TempDir work;
  const Outcome r = run_mresim(work.path(), {"types"});
  std::vector<std::string> types;
  std::istringstream lines(r.out);
  for (std::string type; lines >> type; lines.ignore(1 << 20, '\n')) types.push_back(type);
  return types;
}

// The [run] type of a case's run file, or "" (no file, not TOML, no type).
std::string type_of(const Case& c) {
  const fs::path file = c.dir / "run.toml";
  if (!fs::exists(file)) return "";
  try {
    const toml::table t = toml::parse_file(file.string());
    return t["run"]["type"].value_or(std::string());
  } catch (const toml::parse_error&) {
    return "";
  }
}

TEST(BadInputSuite, HasAtLeast150CasesCoveringEveryRunType) {
  const std::vector<Case> cases = all_cases();
  EXPECT_GE(cases.size(), 150U);
  std::map<std::string, int> per_type;
  for (const Case& c : cases) ++per_type[type_of(c)];
  const auto types = run_types();
  ASSERT_GE(types.size(), 9U);
  for (const std::string& type : types) {
    EXPECT_GE(per_type[type], 5) << "too few bad-input cases for run type " << type;
  }
}

}  // namespace
