#include "fieldvision/util/output_path.h"

#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::util {
namespace {
namespace fs = std::filesystem;

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int CountFiles(const std::string& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(CheckOutputPath, RefusesTheSameFileByNameLinkAndHardLink) {
  const std::string dir = testing::TempDir();
  const std::string in = dir + "/in.csv";
  WriteText(in, "a\n");
  EXPECT_THROW(CheckOutputPath(in, {in}), Error);
  EXPECT_THROW(CheckOutputPath(dir + "/./in.csv", {"", in}), Error);
  fs::create_symlink(in, dir + "/link.csv");
  EXPECT_THROW(CheckOutputPath(dir + "/link.csv", {in}), Error);
  fs::create_hard_link(in, dir + "/hard.csv");
  EXPECT_THROW(CheckOutputPath(dir + "/hard.csv", {in}), Error);
  try {
    CheckOutputPath(in, {in}, "--truth");
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos);
    EXPECT_NE(msg.find("--truth"), std::string::npos);
    EXPECT_NE(msg.find(in), std::string::npos);
  }
  EXPECT_TRUE(SameFile(in, dir + "/./in.csv"));
  EXPECT_TRUE(SameFile(dir + "/link.csv", dir + "/hard.csv"));
  EXPECT_FALSE(SameFile(in, dir + "/out.csv"));
  // Other files, and outputs that do not exist yet, pass.
  EXPECT_NO_THROW(CheckOutputPath(dir + "/out.csv", {in, dir + "/other.csv"}));
  EXPECT_NO_THROW(CheckOutputPath("", {in}));
  const std::vector<std::string> videos = {dir + "/a.avi", in};
  EXPECT_THROW(CheckOutputPath(in, PathList(std::string(), videos, dir + "/b.csv")), Error);
  EXPECT_EQ(ReadText(in), "a\n");
}

TEST(AtomicWrite, ReplacesOnlyOnSuccessAndLeavesNoTemporary) {
  const std::string dir = testing::TempDir();
  const std::string out = dir + "/out.csv";
  WriteText(out, "old\n");
  EXPECT_THROW(AtomicWrite(out,
                           [](const std::string& tmp) {
                             WriteText(tmp, "half");
                             Throw("failed half way");
                           }),
               Error);
  EXPECT_EQ(ReadText(out), "old\n");
  EXPECT_EQ(CountFiles(dir), 1);
  AtomicWrite(out, [](const std::string& tmp) {
    EXPECT_EQ(fs::path(tmp).extension(), ".csv");  // writers pick formats by extension
    WriteText(tmp, "new\n");
  });
  EXPECT_EQ(ReadText(out), "new\n");
  EXPECT_EQ(CountFiles(dir), 1);
  // A writer that wrote nothing does not destroy the output.
  EXPECT_THROW(AtomicWrite(out, [](const std::string&) {}), Error);
  EXPECT_EQ(ReadText(out), "new\n");
}

// A disk that fills up during the write (here: a 64 KB file size limit, RLIMIT_FSIZE, with
// SIGXFSZ ignored so that write() fails as on a full disk): a one-line error, the old output
// kept, no temporary file left.
TEST(AtomicWrite, AFullDiskKeepsTheOutputAndLeavesNoTemporary) {
  const std::string dir = testing::TempDir();
  const std::string out = dir + "/ball.csv";
  WriteText(out, "old\n");
  rlimit was{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &was), 0);
  const auto old_handler = signal(SIGXFSZ, SIG_IGN);
  rlimit small = was;
  small.rlim_cur = rlim_t{64} * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string message;
  try {
    AtomicWrite(out, [](const std::string& tmp) {
      CsvWriter csv(tmp, {"frame", "x_m", "y_m", "z_m"});
      for (int i = 0; i < 100000; ++i) {  // about 3 MB
        csv << i << 0.1 * i << -0.2 * i << 0.11;
        csv.EndRow();
      }
      csv.Close();
    });
  } catch (const Error& e) {
    message = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &was);
  signal(SIGXFSZ, old_handler);
  EXPECT_NE(message.find("error while writing"), std::string::npos) << message;
  EXPECT_NE(message.find(out), std::string::npos) << message;  // the output, not the temporary
  EXPECT_EQ(message.find(".part"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(ReadText(out), "old\n");
  EXPECT_EQ(CountFiles(dir), 1);
}

TEST(AtomicWrite, WritesThroughASymlinkAndRefusesDevicesAndFolders) {
  const std::string dir = testing::TempDir();
  const std::string target = dir + "/target.csv";
  const std::string link = dir + "/link.csv";
  WriteText(target, "old\n");
  fs::create_symlink(target, link);
  AtomicWrite(link, [](const std::string& tmp) { WriteText(tmp, "new\n"); });
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
  EXPECT_EQ(ReadText(target), "new\n");
  EXPECT_THROW(ResolveOutputPath("/dev/null"), Error);
  EXPECT_THROW(ResolveOutputPath(dir), Error);
  EXPECT_THROW(ResolveOutputPath(""), Error);
  EXPECT_EQ(ResolveOutputPath(dir + "/new.csv"), dir + "/new.csv");
  // A missing folder is named with the output, not with the temporary file's name.
  const std::string lost = dir + "/no/such/out.csv";
  EXPECT_NE(testing::ErrorOf([&] { ResolveOutputPath(lost); }).find(lost), std::string::npos);
  // So is a folder that takes no file (/proc, even for root), and nothing is left there.
  const std::string error = testing::ErrorOf([] { AtomicOutput out("/proc/fv_out.csv"); });
  EXPECT_NE(error.find("--out '/proc/fv_out.csv': cannot write a file in folder '/proc'"),
            std::string::npos)
      << error;
  EXPECT_EQ(error.find(".part"), std::string::npos) << error;
  AtomicOutput fine(dir + "/fine.csv");
  EXPECT_FALSE(fs::exists(fine.temp_path()));  // the probe file is gone until a writer writes
}

// A run's new output folder: made with its parents, refused when it holds files or is a file;
// the folders it made go again unless kept, while empty; a folder that was there stays.
TEST(NewFolder, MadeRequiredEmptyAndRemovedUnlessKept) {
  const std::string dir = testing::TempDir();
  {
    NewFolder f(dir + "/a/b/c", "--draw");
    EXPECT_TRUE(fs::is_directory(dir + "/a/b/c"));
  }
  EXPECT_FALSE(fs::exists(dir + "/a")) << "every folder it made is gone";
  {
    NewFolder f(dir + "/kept", "--draw");
    f.Keep();
  }
  EXPECT_TRUE(fs::is_directory(dir + "/kept"));
  {
    NewFolder f(dir + "/kept", "--draw");  // there before: an empty folder is accepted, and stays
  }
  EXPECT_TRUE(fs::is_directory(dir + "/kept"));
  {
    NewFolder f(dir + "/full/sub", "--draw");
    WriteText(dir + "/full/sub/x.txt", "x\n");  // a failed run's partial output stays
  }
  EXPECT_TRUE(fs::exists(dir + "/full/sub/x.txt"));
  const std::string e1 = testing::ErrorOf([&] { NewFolder f(dir + "/full/sub", "--draw"); });
  EXPECT_NE(e1.find("is not empty"), std::string::npos) << e1;
  EXPECT_NE(e1.find("--draw"), std::string::npos) << e1;
  const std::string e2 = testing::ErrorOf([&] { NewFolder f(dir + "/full/sub/x.txt", "--draw"); });
  EXPECT_NE(e2.find("is not a folder"), std::string::npos) << e2;
  EXPECT_EQ(e2.find('\n'), std::string::npos) << e2;
}

// A whole text file through AtomicWrite: written, replaced whole, and a folder or a missing
// folder refused naming what it is, leaving nothing beside it.
TEST(WriteTextFile, WritesWholeOrNothingNamingWhatItIs) {
  const std::string dir = testing::TempDir();
  const std::string path = dir + "/rig.json";
  WriteTextFile(path, "{}\n", "rig file");
  EXPECT_EQ(ReadText(path), "{}\n");
  WriteTextFile(path, "{\"cameras\": []}\n", "rig file");
  EXPECT_EQ(ReadText(path), "{\"cameras\": []}\n");
  fs::create_directories(dir + "/folder.json");
  const std::string folder =
      testing::ErrorOf([&] { WriteTextFile(dir + "/folder.json", "x", "rig file"); });
  EXPECT_NE(folder.find("rig file"), std::string::npos) << folder;
  const std::string missing =
      testing::ErrorOf([&] { WriteTextFile(dir + "/no/such/rig.json", "x", "rig file"); });
  EXPECT_NE(missing.find("rig.json"), std::string::npos) << missing;
  EXPECT_EQ(CountFiles(dir), 2);  // rig.json and folder.json
}

}  // namespace
}  // namespace fv::util
