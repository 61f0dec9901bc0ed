#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace curvesfm::testing {

/// A fixture with an empty folder of its own per test (named after the test and the process, so
/// that parallel ctest runs do not collide), removed afterwards; for readers' tests that write
/// small files.
class TempFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::path(::testing::TempDir()) /
        (std::string(::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
         std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// `name` (a relative path) inside the folder.
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  /// Writes `text` to `name`, creating its folders.
  void write(const std::string& name, const std::string& text) const {
    std::filesystem::create_directories(std::filesystem::path(path(name)).parent_path());
    std::ofstream(path(name)) << text;
  }

  std::filesystem::path dir_;
};

}  // namespace curvesfm::testing
