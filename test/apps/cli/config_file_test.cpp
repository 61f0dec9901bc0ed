#include "apps/cli/config_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "apps/cli/cli_options.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

class ConfigFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    command_ = app_.add_subcommand("demo", "");
    command_->add_option("--max-iterations", iterations_);
    command_->add_option("--kernel", kernel_);
    command_->add_flag("--verbose", verbose_);
    command_->add_option("--config", config_);
    folder_ = std::filesystem::path(::testing::TempDir()) /
              ("config_file_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder_);
  }
  std::string write(const std::string& text) {
    const std::string path = (folder_ / "config.yaml").string();
    std::ofstream(path) << text;
    return path;
  }
  std::string messageOf(const std::string& path) {
    try {
      configFileArguments(path, *command_);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  }

  CLI::App app_;
  CLI::App* command_ = nullptr;
  int iterations_ = 0;
  std::string kernel_, config_;
  bool verbose_ = false;
  std::filesystem::path folder_;
};

TEST_F(ConfigFileTest, TurnsKeysIntoFlags) {
  const auto args =
      configFileArguments(write("max-iterations: 7\nkernel: cauchy\nverbose: true\n"), *command_);
  EXPECT_EQ(args,
            (std::vector<std::string>{"--max-iterations", "7", "--kernel", "cauchy", "--verbose"}));
  EXPECT_TRUE(configFileArguments(write("verbose: false\n"), *command_).empty());
  EXPECT_TRUE(configFileArguments(write(""), *command_).empty());
}

TEST_F(ConfigFileTest, UnknownKeyNamesFileLineAndKey) {
  const std::string message = messageOf(write("kernel: huber\nmax-iteration: 3\n"));
  EXPECT_NE(message.find("config.yaml:2:"), std::string::npos) << message;
  EXPECT_NE(message.find("'max-iteration'"), std::string::npos) << message;
}

TEST_F(ConfigFileTest, MalformedYamlNamesFileAndLine) {
  const std::string message = messageOf(write("kernel: huber\nmax-iterations: [3\n"));
  EXPECT_EQ(message.rfind("ParseError: ", 0), 0u) << message;
  EXPECT_NE(message.find("config.yaml:"), std::string::npos) << message;
}

TEST_F(ConfigFileTest, BadFlagValueAndNestingAreRejected) {
  EXPECT_NE(messageOf(write("verbose: maybe\n")).find("config.yaml:1:"), std::string::npos);
  EXPECT_NE(messageOf(write("kernel:\n  type: huber\n")).find("nested mapping"), std::string::npos);
}

TEST_F(ConfigFileTest, MissingFileIsAnIoError) {
  EXPECT_THROW(configFileArguments((folder_ / "absent.yaml").string(), *command_), IoError);
}

TEST_F(ConfigFileTest, EffectiveOptionsRoundTripThroughYaml) {
  app_.parse(std::vector<std::string>{"3", "--max-iterations", "demo"});
  const std::string yaml = effectiveOptionsYaml(*command_);
  EXPECT_NE(yaml.find("max-iterations: 3"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("verbose: false"), std::string::npos) << yaml;
  const auto args = configFileArguments(write(yaml), *command_);
  EXPECT_EQ(args[0], "--max-iterations");
  EXPECT_EQ(args[1], "3");
}

TEST_F(ConfigFileTest, EffectiveOptionsGiveTheValueInForce) {
  // As in curvesfm: a flag from the config file and again on the command line, the last wins.
  command_->get_option("--max-iterations")->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app_.parse(std::vector<std::string>{"9", "--max-iterations", "3", "--max-iterations", "demo"});
  EXPECT_EQ(iterations_, 9);
  const std::string yaml = effectiveOptionsYaml(*command_);
  EXPECT_NE(yaml.find("max-iterations: 9\n"), std::string::npos) << yaml;
}

TEST_F(ConfigFileTest, AProgramWithoutSubcommandsReadsItsOwnConfigFlag) {
  // As planar_bench: the flags, --config among them, belong to the program itself.
  CLI::App program;
  program.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  int iterations = 0;
  std::string kernel;
  program.add_option("--max-iterations", iterations);
  program.add_option("--kernel", kernel);
  addConfigFlag(&program);
  const std::string path = write("max-iterations: 7\nkernel: cauchy\n");
  parseCommandLine(&program, {"--config", path, "--kernel", "huber"});
  EXPECT_EQ(iterations, 7);
  EXPECT_EQ(kernel, "huber");  // The command line wins over the file.
}

}  // namespace
}  // namespace curvesfm
