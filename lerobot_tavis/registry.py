"""Everything that can be named in a run: tasks (with their suite, splits, prompts, task class and demonstrator),
robots and camera modes, in one import that loads neither MuJoCo, torch nor LeRobot.

Each kind is declared once, in its own registry module: tasks in `envs.tasks.catalog`, robots in `envs.robots`,
camera modes in `envs.modes`. The command line, `TavisEnvConfig` and the demo read their choices from these.
A task, robot or camera mode from outside the package joins with `register_task`, `register_robot` or
`register_camera_mode` (docs/extending.md; tests/test_registry.py registers one of each and runs them).
"""

from lerobot_tavis.envs.modes import (CAMERA_MODES, DEFAULT_CAMERA_MODE, camera_mode_names, mode_cameras,
                                      register_camera_mode, unregister_camera_mode)
from lerobot_tavis.envs.robots import (DEFAULT_ROBOT, ROBOTS, RobotInfo, make_robot, register_robot, robot_info,
                                       robot_names, unregister_robot)
from lerobot_tavis.envs.tasks.catalog import (BENCHMARK_TASKS, SPLITS, SUITES, TASKS, TaskInfo, demonstrator_class,
                                              register_task, split_names, suite_names, suite_tasks, task_class,
                                              task_info, task_names, unregister_task)

__all__ = [
    "BENCHMARK_TASKS", "CAMERA_MODES", "DEFAULT_CAMERA_MODE", "DEFAULT_ROBOT", "ROBOTS", "SPLITS", "SUITES", "TASKS",
    "RobotInfo", "TaskInfo", "camera_mode_names", "demonstrator_class", "make_robot", "mode_cameras",
    "register_camera_mode", "register_robot", "register_task", "robot_info", "robot_names", "split_names",
    "suite_names", "suite_tasks", "task_class", "task_info", "task_names", "unregister_camera_mode",
    "unregister_robot", "unregister_task",
]
