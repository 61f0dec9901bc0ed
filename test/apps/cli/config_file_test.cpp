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

// No flag takes several values, so a list is an error wherever it stands, naming the line where
// the list starts and the key.
TEST_F(ConfigFileTest, FlowListIsAnErrorNamingFileLineAndKey) {
  const std::string path = write("verbose: true\nkernel: [huber, cauchy]\n");
  EXPECT_EQ(messageOf(path),
            "ParseError: " + path + ":2: expected a single value for flag 'kernel', found a list");
}

TEST_F(ConfigFileTest, BlockListIsAnErrorNamingFileLineAndKey) {
  const std::string path = write("kernel: huber\nmax-iterations:\n  - 3\n  - 4\n");
  const std::string message = messageOf(path);
  EXPECT_EQ(message.rfind("ParseError: " + path + ":3: ", 0), 0u) << message;
  EXPECT_NE(message.find("a single value for flag 'max-iterations', found a list"),
            std::string::npos)
      << message;
  // A switch given as a list is refused the same way, not read as true or false.
  EXPECT_NE(messageOf(write("verbose:\n  - true\n"))
                .find(":2: expected a single value for flag "
                      "'verbose', found a list"),
            std::string::npos);
}

TEST_F(ConfigFileTest, RepeatedKeyIsAnErrorNamingFileLineAndKey) {
  const std::string path = write("kernel: huber\nmax-iterations: 3\nkernel: cauchy\n");
  EXPECT_EQ(messageOf(path), "ParseError: " + path +
                                 ":3: expected each flag once, found 'kernel' again (first on "
                                 "line 1)");
  // Switches too: yaml-cpp keeps both entries, and neither may silently win.
  EXPECT_NE(messageOf(write("verbose: true\nverbose: false\n"))
                .find("config.yaml:2: expected each flag once, found 'verbose' again"),
            std::string::npos);
}

TEST_F(ConfigFileTest, KeyThatIsNotANameIsAnErrorNamingFileAndLine) {
  const std::string message = messageOf(write("kernel: huber\n[max-iterations]: 3\n"));
  EXPECT_NE(message.find("config.yaml:2: expected a flag name as key, found a list"),
            std::string::npos)
      << message;
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
