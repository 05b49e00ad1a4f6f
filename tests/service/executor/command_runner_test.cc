// RunCommand: a program's exit status and both outputs, arguments passed without a shell, the
// environment added on top, a program that cannot start and one that runs too long.
#include "executor/command_runner.h"

#include <gtest/gtest.h>

namespace seep::service {
namespace {

using std::chrono::milliseconds;

TEST(CommandRunner, ExitStatusAndBothOutputs) {
  auto out = RunCommand({"sh", "-c", "echo out; echo err >&2; exit 3"}, {}, milliseconds(10000));
  ASSERT_TRUE(out.ok()) << out.status().ToString();
  EXPECT_EQ(out->exit_code, 3);
  EXPECT_EQ(out->out, "out\n");
  EXPECT_EQ(out->err, "err\n");
}

TEST(CommandRunner, ArgumentsReachTheProgramAsTheyAre) {
  auto out = RunCommand({"printf", "%s|", "a b", "$HOME", "'q'"}, {}, milliseconds(10000));
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(out->out, "a b|$HOME|'q'|");
}

TEST(CommandRunner, TheEnvironmentIsAddedOnTop) {
  auto out = RunCommand({"sh", "-c", "echo $SEEP_TEST_VALUE"}, {{"SEEP_TEST_VALUE", "42"}},
                        milliseconds(10000));
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(out->out, "42\n");
}

TEST(CommandRunner, AProgramThatCannotStartIsUnavailableNamingIt) {
  auto out = RunCommand({"seep-no-such-program"}, {}, milliseconds(10000));
  ASSERT_FALSE(out.ok());
  EXPECT_EQ(out.status().code(), core::StatusCode::kUnavailable);
  EXPECT_NE(out.status().message().find("seep-no-such-program"), std::string::npos);
}

TEST(CommandRunner, AProgramThatRunsTooLongIsKilled) {
  const auto start = std::chrono::steady_clock::now();
  auto out = RunCommand({"sleep", "30"}, {}, milliseconds(300));
  ASSERT_FALSE(out.ok());
  EXPECT_EQ(out.status().code(), core::StatusCode::kUnavailable);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
}

}  // namespace
}  // namespace seep::service
