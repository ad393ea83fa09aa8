"""Vector envs for `--env.type=tavis` whose worker processes stay lean: they import neither torch nor LeRobot.

LeRobot's own lazy async vector env wraps every sub-env factory in a closure of `lerobot.envs.utils`, so each
worker that unpickles one imports that module, and with it torch, which multiplies a worker's memory (docs/
benchmarks.md, "Worker footprint") and so the memory of a protocol's many env workers. This module gives the same
two behaviours from classes that import only gymnasium:

- `FreezeAfterEpisodeEnd`: once a sub-env's episode has ended, further steps and Gymnasium's autoresets replay its
  terminal transition (reward 0) instead of simulating, until an explicit reset carrying LeRobot's new-rollout
  option (`NEW_ROLLOUT_OPTION`, the key lerobot-eval's rollout passes) starts the next episode.
- `LazyAsyncVectorEnv`: the AsyncVectorEnv (forkserver workers, shared memory, next-step autoreset) is created on
  first use, so one task's workers are alive at a time while lerobot-eval walks a suite. Only its first
  `filmed_envs` sub-envs draw video frames: lerobot-eval films at most 10 episodes of a batch, from its first
  sub-envs, yet asks every sub-env of an async batch for a frame at each step (the overview rendered,
  composed and sent through a pipe); the others answer `render()` with None, and `call("render")`
  returns the filmed ones' frames alone, so that lerobot-eval films `min(filmed_envs, 10)` episodes. lerobot-eval
  also asks every sub-env for its `task_description` at each step, a round trip through all the workers that the
  policy's process waits for; a prompt changes only at a reset, so it is asked once per reset.
  `worker_niceness` lowers the workers' CPU priority (added to their niceness, as `nice`), so that the process that
  runs the policy is not delayed by them when the cores are contended. `retarget` gives started workers other
  sub-envs (another task or split, same spaces) without starting new processes, and without waiting for them.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import gymnasium as gym

from lerobot_tavis.process import children_skip_main_module

NEW_ROLLOUT_OPTION = "lerobot_new_rollout"  # lerobot.envs.utils.NEW_ROLLOUT_OPTION (a test keeps them equal)


class FreezeAfterEpisodeEnd(gym.Wrapper):
    """A sub-env that costs nothing between the end of its episode and the next rollout's reset."""

    def __init__(self, env: gym.Env):
        super().__init__(env)
        self._terminal: tuple | None = None

    def reset(self, *, seed=None, options=None):
        if self._terminal is not None and not (options or {}).get(NEW_ROLLOUT_OPTION):
            observation, _, _, _, info = self._terminal  # an autoreset of an episode the rollout is done with
            return observation, info
        self._terminal = None
        return self.env.reset(seed=seed, options=options)

    def step(self, action):
        if self._terminal is not None:
            return self._terminal
        observation, reward, terminated, truncated, info = self.env.step(action)
        if terminated or truncated:
            self._terminal = (observation, 0.0, terminated, truncated, info)
        return observation, reward, terminated, truncated, info


class Unfilmed(gym.Wrapper):
    """A sub-env whose frames nobody films: `render()` returns None and costs nothing."""

    def render(self):
        return None


@dataclass(frozen=True)
class Frozen:
    """A sub-env factory whose env freezes after its episode (picklable by reference to this module); an env not
    `filmed` renders no frame."""

    make: Callable[[], gym.Env]
    filmed: bool = True

    def __call__(self) -> gym.Env:
        env = FreezeAfterEpisodeEnd(self.make())
        return env if self.filmed else Unfilmed(env)


class Retargetable(gym.Wrapper):
    """The sub-env an async worker process holds: `retarget(factories)` closes the env it wraps and builds
    `factories[index]()` in its place, in the same process."""

    def __init__(self, factories: Sequence[Callable[[], gym.Env]], index: int):
        super().__init__(factories[index]())
        self.index = index

    def retarget(self, factories: Sequence[Callable[[], gym.Env]]) -> None:
        self.env.close()
        self.env = factories[self.index]()


@dataclass(frozen=True)
class WorkerEnv:
    """Builds sub-env `index` of `factories` as a `Retargetable`, first adding `niceness` to the niceness (as `nice`)
    of any process that calls it other than `creator_pid`, the one that built it: gymnasium's AsyncVectorEnv also
    calls its first factory there, for the spaces, and that process must keep its priority."""

    factories: tuple[Frozen, ...]
    index: int
    niceness: int = 0
    creator_pid: int = field(default_factory=os.getpid)

    def __call__(self) -> gym.Env:
        if self.niceness and os.getpid() != self.creator_pid:
            os.nice(self.niceness)
        return Retargetable(self.factories, self.index)


class LazyAsyncVectorEnv:
    """An AsyncVectorEnv of `Frozen(factory)` sub-envs, started on the first reset, step, call or attribute read.
    `observation_space`, `action_space` and `metadata` are those of one sub-env, given up front; sub-envs from
    index `filmed_envs` on render no frame; `worker_niceness` is added to each worker process's niceness (as
    `nice`)."""

    def __init__(self, factories: list[Callable[[], gym.Env]], observation_space: gym.Space,
                 action_space: gym.Space, metadata: dict, filmed_envs: int = 10, worker_niceness: int = 0):
        self._worker_niceness = worker_niceness
        self._env: gym.vector.AsyncVectorEnv | None = None
        self._retargeting = False  # the workers were asked to retarget and have not all answered yet
        self._set_factories(factories, filmed_envs)
        self.num_envs = len(factories)
        self.observation_space = self.single_observation_space = observation_space
        self.action_space = self.single_action_space = action_space
        self.metadata = metadata

    def _set_factories(self, factories: list[Callable[[], gym.Env]], filmed_envs: int) -> None:
        self._frozen = tuple(Frozen(factory, filmed=index < filmed_envs) for index, factory in enumerate(factories))
        self._filmed_envs = filmed_envs
        self._task_descriptions: tuple[str, ...] | None = None  # the sub-envs' prompts since the last reset

    def retarget(self, factories: list[Callable[[], gym.Env]], filmed_envs: int) -> None:
        """Serve the sub-envs of `factories` (as many as now, with the same spaces: another task or split) from the
        next reset on. Started workers close their sub-env and build the new one in the same process, so its
        imports and its GL context are not paid again; only the first `filmed_envs` of them draw frames. This
        returns at once: the workers build while this process goes on (a policy job loads its policy meanwhile),
        and the next use of the batch waits for them (and raises a worker's error)."""
        if len(factories) != self.num_envs:
            raise ValueError(f"retarget: {len(factories)} sub-env factories for a batch of {self.num_envs}")
        self._set_factories(factories, filmed_envs)
        if self._env is not None:
            self._started().call_async("retarget", self._frozen)
            self._retargeting = True

    @property
    def unwrapped(self) -> LazyAsyncVectorEnv:
        return self

    def _started(self) -> gym.vector.AsyncVectorEnv:
        if self._env is None:
            workers = [WorkerEnv(self._frozen, index, self._worker_niceness) for index in range(self.num_envs)]
            with children_skip_main_module():  # under lerobot-eval, its script would bring torch into every worker
                self._env = gym.vector.AsyncVectorEnv(workers, context="forkserver", shared_memory=True,
                                                      autoreset_mode=gym.vector.AutoresetMode.NEXT_STEP)
        elif self._retargeting:
            self._retargeting = False
            self._env.call_wait()
        return self._env

    def reset(self, **kwargs):
        self._task_descriptions = None
        return self._started().reset(**kwargs)

    def step(self, actions):
        return self._started().step(actions)

    def call(self, name: str, *args, **kwargs):
        """Each sub-env's `name(*args, **kwargs)`; for "render", only the frames of the filmed sub-envs (the
        first ones), so that lerobot-eval stacks and films as many episodes as draw frames; "task_description" is
        asked of the workers once per reset."""
        if name == "task_description":
            if self._task_descriptions is None:
                self._task_descriptions = self._started().call(name)
            return self._task_descriptions
        results = self._started().call(name, *args, **kwargs)
        return results[:self._filmed_envs] if name == "render" else results

    def get_attr(self, name: str):
        return self._started().get_attr(name)

    def close(self) -> None:
        if self._env is not None:
            self._env.close()  # waits for a retarget still under way
            self._env = None
            self._retargeting = False
