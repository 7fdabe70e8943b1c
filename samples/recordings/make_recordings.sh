#!/usr/bin/env bash
# Makes the sample recordings from the tool-up exercise (run from anywhere; needs moveplan installed).
# Each recording is an executed file from `moveplan execute --fake -o`, which carries /joint_states
# like a `ros2 bag record` of a real robot would.
set -euo pipefail
cd "$(dirname "$0")"
moveplan plan ../ur10e_tool_up.yaml --seed 0 -o tool_up_plan.mcap -q
# Follows the plan: passes.
moveplan execute tool_up_plan.mcap --fake -o tool_up_ok.mcap -q
# A 0.25 rad bump on wrist_1 half way: violates the 0.2 rad path tolerance.
moveplan execute tool_up_plan.mcap --fake --disturb "t=0.5,joint=wrist_1_joint,delta=0.25" \
  -o tool_up_path_violation.mcap -q || true
# A sluggish robot (first-order lag, 0.2 s): misses a 2 mrad goal tolerance within goal_time 0.3 s.
moveplan execute tool_up_plan.mcap --fake --plant lag --plant-param tau=0.2 \
  --controllers ur10e_goal_time_controllers.yaml -o tool_up_goal_missed.mcap -q || true
