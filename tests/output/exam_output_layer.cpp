// exam_output_layer — all-or-nothing output as a command sees it (backlash/output/): a staged
// folder appears whole on commit and leaves nothing when abandoned; a partial folder is kept
// for a resume; an atomic file replaces only a regular file; every refusal is a bad_target
// OutputError (exit 2) before anything is written, every failed write a write_failed one
// (exit 1) that leaves nothing behind.
#include "backlash/output/atomic_file.hpp"
#include "backlash/output/output_error.hpp"
#include "backlash/output/staged_directory.hpp"
#include "backlash/output/target.hpp"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using backlash::output::AtomicFile;
using backlash::output::check_target;
using backlash::output::FolderOwner;
using backlash::output::OutputError;
using backlash::output::OutputFiles;
using backlash::output::Problem;
using backlash::output::StagedDirectory;
using backlash::output::Target;

/// A fresh folder under the system's temporary folder, removed with its content.
class Scratch {
 public:
  Scratch() {
    std::random_device entropy;
    path_ = fs::temp_directory_path() / ("backlash-output-" + std::to_string(::getpid()) + "-" + std::to_string(entropy()));
    fs::create_directories(path_);
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  fs::path operator/(const std::string& name) const { return path_ / name; }
  const fs::path& path() const { return path_; }
  /// The names in the folder, sorted (hidden ones included).
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& entry : fs::directory_iterator(path_)) out.push_back(entry.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  fs::path path_;
};

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void put(const fs::path& file, const std::string& text) { std::ofstream(file, std::ios::binary) << text; }

/// The OutputError `action` throws (fails the test when it throws none).
OutputError error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const OutputError& error) {
    return error;
  }
  ADD_FAILURE() << "no OutputError thrown";
  return OutputError(OutputError::Kind::write_failed, Problem::write_failed, "", "", "none");
}

void expect_refusal(const OutputError& error, Problem problem, const std::string& message) {
  EXPECT_EQ(error.kind(), OutputError::Kind::bad_target) << error.what();
  EXPECT_EQ(error.exit_code(), 2);
  EXPECT_EQ(error.problem(), problem) << error.what();
  EXPECT_EQ(std::string(error.what()), message);
}

// ------------------------------------------------------------------ staged folders

TEST(StagedFolder, AppearsWholeOnCommitWithItsMarker) {
  Scratch scratch;
  const fs::path target = scratch / "report";
  {
    StagedDirectory stage(target);
    stage.write("a.md", "alpha\n");
    stage.write("figures/b.csv", "1,2\n");
    EXPECT_FALSE(fs::exists(target)) << "visible before commit";
    EXPECT_EQ(stage.path().parent_path(), scratch.path());
    EXPECT_EQ(stage.path().filename().string().rfind(".report.tmp-", 0), 0u) << stage.path();
    stage.commit();
  }
  EXPECT_EQ(slurp(target / "a.md"), "alpha\n");
  EXPECT_EQ(slurp(target / "figures/b.csv"), "1,2\n");
  EXPECT_EQ(slurp(target / ".backlash-report"), "written by backlash report\n");
  EXPECT_EQ(scratch.names(), std::vector<std::string>{"report"}) << "a staging or old folder left behind";
}

TEST(StagedFolder, AbandonedLeavesNothingAndKeepsTheOldOutput) {
  Scratch scratch;
  const fs::path target = scratch / "out";
  {
    StagedDirectory first(target, "discrepancy");
    first.write("page.md", "old\n");
    first.commit();
  }
  try {
    StagedDirectory stage(target);
    stage.write("page.md", "new\n");
    throw std::runtime_error("the computation failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(slurp(target / "page.md"), "old\n");
  EXPECT_EQ(scratch.names(), std::vector<std::string>{"out"});
}

TEST(StagedFolder, ReplacesOnlyAnEmptyFolderOrTheProjectsOwn) {
  Scratch scratch;
  fs::create_directory(scratch / "empty");
  StagedDirectory onto_empty(scratch / "empty");
  onto_empty.write("x", "1");
  onto_empty.commit();
  EXPECT_EQ(slurp(scratch / "empty/x"), "1");

  StagedDirectory again(scratch / "empty");  // holds the marker now
  again.write("y", "2");
  again.commit();
  EXPECT_FALSE(fs::exists(scratch / "empty/x")) << "the old output was merged, not replaced";
  EXPECT_EQ(slurp(scratch / "empty/y"), "2");

  fs::create_directory(scratch / "home");
  put(scratch / "home/notes.txt", "mine");
  const fs::path home = scratch / "home";
  expect_refusal(error_of([&] { StagedDirectory stage(home); }), Problem::foreign_folder,
                 "--out " + home.string() + ": the folder exists and is not a backlash report; choose a new folder");
  expect_refusal(error_of([&] { check_target(home, Target::folder, FolderOwner{"backlash output"}); }),
                 Problem::foreign_folder,
                 "--out " + home.string() + ": the folder exists and is not a backlash output; choose a new folder");
  EXPECT_EQ(slurp(scratch / "home/notes.txt"), "mine");
}

TEST(StagedFolder, RefusesAFileASymbolicLinkAndAMissingParent) {
  Scratch scratch;
  put(scratch / "file", "keep");
  expect_refusal(error_of([&] { StagedDirectory stage(scratch / "file"); }), Problem::not_a_folder,
                 "--out " + (scratch / "file").string() + ": exists and is not a folder");
  fs::create_directory(scratch / "real");
  fs::create_directory_symlink(scratch / "real", scratch / "link");
  expect_refusal(error_of([&] { check_target(scratch / "link", Target::folder); }), Problem::not_a_folder,
                 "--out " + (scratch / "link").string() + ": exists and is not a folder");
  const fs::path deep = scratch / "absent" / "out";
  expect_refusal(error_of([&] { check_target(deep, Target::folder); }), Problem::folder_missing,
                 "--out " + deep.string() + ": the folder " + (scratch / "absent").string() + " does not exist");
  expect_refusal(error_of([&] { check_target("", Target::folder); }), Problem::empty_name, "--out: empty path");
  expect_refusal(error_of([&] { check_target("/", Target::folder); }), Problem::not_a_name, "--out /: not a folder name");
  EXPECT_EQ(slurp(scratch / "file"), "keep");
}

TEST(StagedFolder, APartialFolderIsKeptForAResumeAndCommittedLater) {
  Scratch scratch;
  const fs::path target = scratch / "map";
  EXPECT_EQ(StagedDirectory::partial_path(target, "map-partial"), scratch / ".map.map-partial");
  {
    StagedDirectory stage = StagedDirectory::partial(target, "map-partial", "map", FolderOwner{"backlash output"});
    fs::create_directory(stage.path());
    stage.write("points.csv", "index\n0\n");
  }  // interrupted: no commit
  EXPECT_EQ(slurp(scratch / ".map.map-partial/points.csv"), "index\n0\n");
  EXPECT_FALSE(fs::exists(target));
  {
    StagedDirectory stage = StagedDirectory::partial(target, "map-partial", "map", FolderOwner{"backlash output"});
    stage.write("points.csv", "index\n0\n1\n");  // resumed
    stage.commit();
  }
  EXPECT_EQ(slurp(target / "points.csv"), "index\n0\n1\n");
  EXPECT_EQ(slurp(target / ".backlash-report"), "written by backlash map\n");
  EXPECT_EQ(scratch.names(), std::vector<std::string>{"map"});
}

TEST(StagedFolder, AFailedWriteIsAWriteFailureAndLeavesNothing) {
  Scratch scratch;
  {
    StagedDirectory stage(scratch / "out");
    fs::create_directories(stage.path() / "taken");  // a folder where the file should go
    const OutputError error = error_of([&] { stage.write("taken", "x"); });
    EXPECT_EQ(error.kind(), OutputError::Kind::write_failed);
    EXPECT_EQ(error.exit_code(), 1);
    EXPECT_EQ(std::string(error.what()), "cannot write " + (stage.path() / "taken").string());
  }
  EXPECT_TRUE(scratch.names().empty()) << scratch.names().front();
}

// ------------------------------------------------------------------ atomic files

TEST(AtomicFile, ReplacesARegularFileOnlyOnCommit) {
  Scratch scratch;
  const fs::path target = scratch / "sweep.csv";
  put(target, "old\n");
  ::chmod(target.c_str(), 0640);
  {
    AtomicFile file(target);
    file.write("a,b\n");
    file.write("1,2\n");
    EXPECT_EQ(slurp(target), "old\n") << "replaced before commit";
    file.commit();
  }
  EXPECT_EQ(slurp(target), "a,b\n1,2\n");
  EXPECT_EQ(fs::status(target).permissions() & fs::perms::all, fs::perms(0640)) << "the replaced file's permissions";
  {
    AtomicFile abandoned(target);
    abandoned.write("never\n");
  }
  EXPECT_EQ(slurp(target), "a,b\n1,2\n");
  EXPECT_EQ(scratch.names(), std::vector<std::string>{"sweep.csv"}) << "a temporary file left behind";
}

TEST(AtomicFile, RefusesADirectoryASymbolicLinkAndADevice) {
  Scratch scratch;
  fs::create_directory(scratch / "folder");
  expect_refusal(error_of([&] { AtomicFile file(scratch / "folder"); }), Problem::is_directory,
                 "--out " + (scratch / "folder").string() + ": is a directory; give a file name");
  put(scratch / "real.csv", "mine");
  fs::create_symlink(scratch / "real.csv", scratch / "link.csv");
  expect_refusal(error_of([&] { AtomicFile file(scratch / "link.csv"); }), Problem::is_symlink,
                 "--out " + (scratch / "link.csv").string() +
                     ": is a symbolic link; refusing to replace it (give the file itself)");
  const OutputError device = error_of([&] { AtomicFile file("/dev/null"); });
  expect_refusal(device, Problem::not_regular,
                 "--out /dev/null: is not a regular file (a device, a pipe or a socket); refusing to replace it");
  EXPECT_EQ(device.detail(), "a character device");
  ::mkfifo((scratch / "fifo").c_str(), 0600);
  EXPECT_EQ(error_of([&] { AtomicFile file(scratch / "fifo"); }).detail(), "a FIFO");
  expect_refusal(error_of([&] { AtomicFile file(scratch / "absent" / "x.csv"); }), Problem::folder_missing,
                 "--out " + (scratch / "absent" / "x.csv").string() + ": the folder " + (scratch / "absent").string() +
                     " does not exist");
  expect_refusal(error_of([&] { AtomicFile file(""); }), Problem::empty_name, "--out '': not a file name");
  expect_refusal(error_of([&] { AtomicFile file(scratch / ".."); }), Problem::not_a_name,
                 "--out '" + (scratch / "..").string() + "': not a file name");
  EXPECT_EQ(slurp(scratch / "real.csv"), "mine");
  EXPECT_EQ(scratch.names(), (std::vector<std::string>{"fifo", "folder", "link.csv", "real.csv"}));
}

TEST(AtomicFile, AFailedWriteIsAWriteFailureAndLeavesNothing) {
  // A full disk, simulated: a file-size limit makes write() fail with EFBIG (even for root).
  Scratch scratch;
  const fs::path target = scratch / "big.csv";
  put(target, "old\n");
  rlimit saved{};
  ::getrlimit(RLIMIT_FSIZE, &saved);
  const auto previous = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = saved;
  small.rlim_cur = 4096;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  const OutputError error = error_of([&] {
    AtomicFile file(target);
    file.write(std::string(200000, 'x'));
    file.commit();
  });
  ::setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, previous);
  EXPECT_EQ(error.kind(), OutputError::Kind::write_failed) << error.what();
  EXPECT_EQ(error.exit_code(), 1);
  EXPECT_EQ(error.problem(), Problem::write_failed);
  EXPECT_EQ(std::string(error.what()).rfind("cannot write " + target.string() + ": ", 0), 0u) << error.what();
  EXPECT_EQ(slurp(target), "old\n");
  EXPECT_EQ(scratch.names(), std::vector<std::string>{"big.csv"});
}

TEST(OutputFiles, ChecksEveryTargetBeforeWritingAny) {
  Scratch scratch;
  fs::create_directories(scratch / "gen/case_V.tex");  // a folder where the second file goes
  OutputFiles files;
  files.add("case_V.hpp", "// header\n");
  files.add("case_V.tex", "% tex\n");
  const OutputError error = error_of([&] { files.commit(scratch / "gen"); });
  EXPECT_EQ(error.problem(), Problem::is_directory);
  EXPECT_FALSE(fs::exists(scratch / "gen/case_V.hpp")) << "the first file was written before the refusal";

  put(scratch / "plain", "x");
  expect_refusal(error_of([&] { files.commit(scratch / "plain"); }), Problem::not_a_folder,
                 "--out " + (scratch / "plain").string() + ": exists and is not a folder");

  files.commit(scratch / "new/sub");
  EXPECT_EQ(slurp(scratch / "new/sub/case_V.hpp"), "// header\n");
  EXPECT_EQ(slurp(scratch / "new/sub/case_V.tex"), "% tex\n");
}

}  // namespace
