// `navbus command`: an operator's FilterCommand reaches a running navbus-filter, which applies
// it or refuses it (an issuer not in its command_issuers), and the tool prints the filter's
// answer (exit 0 applied, 1 refused); bad options exit 2 naming the option and the value; with
// no filter on the domain the tool says so and exits 1. Domain 67.
#include <gtest/gtest.h>

#include "harness.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace std::chrono_literals;

namespace {

constexpr int kDomain = 67;

int runTool(const std::filesystem::path& dir, const std::string& log,
            std::vector<std::string> args) {
  args.insert(args.begin(), {"-d", std::to_string(kDomain), "command"});
  test::ChildProcess tool(navbus::test_paths::toolExe(), args, (dir / log).string());
  return tool.wait(30s).value_or(-1);
}

}  // namespace

TEST(CommandTool, AppliedRefusedAndBadOptions) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("command");
  const std::string filter_cfg = test::writeFile(
      dir / "filter.yaml", "extends: " + std::string(navbus::test_paths::configDir()) +
                               "/filter.yaml\n" + "domain_id: " + std::to_string(kDomain) + "\n");

  // No filter yet: nobody reads the commands.
  EXPECT_EQ(runTool(dir, "none.log", {"RESET", "--match-timeout", "0.5"}), 1);
  EXPECT_NE(test::readFile(dir / "none.log").find("no reader of navbus/filter/command"),
            std::string::npos);

  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  EXPECT_EQ(
      runTool(dir, "ok.log", {"EXCLUDE_STREAM", "--sensor", "GNSS_FIX_STREAM", "--sensor-id", "1"}),
      0)
      << test::readFile(dir / "ok.log");
  EXPECT_NE(test::readFile(dir / "ok.log").find("vehicle 1: APPLIED"), std::string::npos)
      << test::readFile(dir / "ok.log");
  EXPECT_EQ(runTool(dir, "intruder.log", {"CMD_RESET", "--issuer", "intruder"}), 1);
  EXPECT_NE(
      test::readFile(dir / "intruder.log")
          .find("vehicle 1: REFUSED (unauthorized): issuer 'intruder' not in command_issuers"),
      std::string::npos)
      << test::readFile(dir / "intruder.log");

  EXPECT_EQ(runTool(dir, "bad.log", {"SELECT_FUSION", "--fusion", "BOGUS"}), 2);
  EXPECT_NE(test::readFile(dir / "bad.log")
                .find("--fusion: 'BOGUS' is not one of NONE, CENTRALIZED, FEDERATED, ADAPTIVE"),
            std::string::npos)
      << test::readFile(dir / "bad.log");
  EXPECT_EQ(runTool(dir, "axis.log", {"COMPENSATE_BIAS", "--sensor", "GYRO", "--axis", "3"}), 2);
  EXPECT_NE(test::readFile(dir / "axis.log").find("--axis 3 must be 0, 1 or 2"), std::string::npos);

  filter.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  const std::string log = test::readFile(dir / "filter.log");
  EXPECT_NE(log.find("commands applied 1 refused 1 (unauthorized issuer 1,"), std::string::npos)
      << log;
  EXPECT_NE(log.find("'intruder' refused: not a configured issuer"), std::string::npos) << log;
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}
