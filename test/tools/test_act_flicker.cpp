// act_flicker as a user runs it: one family scene, its six kinds of light that comes and goes in
// rows against the light-matched references, the control row and the summary lines; bad arguments
// refused.
#include <gtest/gtest.h>

#include <string>

#include "tool_test_util.hpp"

namespace {

using act_color_tool_test::ToolRun;
ToolRun run(const std::string& arguments) {
  return act_color_tool_test::runTool("act_flicker", arguments, act_color_tool_test::tempDir("act_flicker_test"));
}

}  // namespace

TEST(ActFlicker, PrintsEveryKindOfFlickerAgainstSteadyLight) {
  const ToolRun r = run("--seeds 0-0 --frames 40");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* row :
       {"seed 0 every other frame at half", "seed 0 one frame in ten at half", "seed 0 exposure 1 +- 0.3 at 1 Hz",
        "seed 0 exposure 1 +- 0.3 at 15 Hz", "seed 0 control: steady, fresh noise"}) {
    EXPECT_NE(r.output.find(row), std::string::npos) << row << "\n" << r.output;
  }
  EXPECT_NE(r.output.find("6 runs: fill within 1.5x in"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 controls (no flicker, fresh noise): every class's precision within 0.03 in"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(run("--seeds 3-1").exit_code, 2);
  EXPECT_EQ(run("--frames 5").exit_code, 2);
  EXPECT_EQ(run("--bogus").exit_code, 2);
}
