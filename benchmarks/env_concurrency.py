"""Env steps per second of many env processes at once on one machine: the ceiling a policy evaluation's env
workers can reach, with the camera mode's cameras rendered or with none; and, with `--policy-batch`, how long the
reference Diffusion Policy takes per action chunk in the main process meanwhile (does rendering slow inference on
a shared GPU?).

    python benchmarks/env_concurrency.py [--seconds 12] [--render 1 16 48 96] [--no-render 96]
                                         [--camera-mode head_wrist] [--image-size 240x320]
                                         [--policy-batch 32 [--denoising-steps 10] [--policy-arg=--policy.x=y ...]]

Each count starts that many processes (spawned, one GL context each, like lerobot-eval's async env workers); each
builds a conditional_pick env (GR1T2, seed 1000), resets it, then, once all are ready, steps it for `--seconds`
holding its measured pose. Prints one Markdown row per count: env steps per second over all processes and the CPU
cores they kept busy. With MUJOCO_GL=egl the renders go to the GPU where there is one. With `--policy-batch B` the
main process builds the `diffusion_head_wrist` preset's policy (random weights, DDIM, AMP on a GPU) and generates
action chunks for B envs from random observations during the same window, alone first (0 processes): milliseconds
per chunk, GPU time included (the first chunk untimed; e.g. `--policy-arg=--policy.compile_model=true` times
LeRobot's torch.compile of the denoising network).
"""

from __future__ import annotations

import argparse
import contextlib
import multiprocessing as mp
import os
import time

os.environ.setdefault("MUJOCO_GL", "egl")


def _step_for(seconds: float, render: bool, camera_mode: str, size: tuple[int, int], ready, results) -> None:
    from lerobot_tavis.envs.env import TavisEnv

    env = TavisEnv("conditional_pick", "gr1t2", camera_mode=camera_mode, split="id", image_size=size,
                   episode_length_s=1e6, cameras=None if render else ())
    observation, _ = env.reset(seed=1000)
    hold = observation["agent_pos"].copy()
    env.step(hold)  # the first step builds what is built lazily (the GL context among it)
    ready.wait()
    end, steps, cpu_start = time.perf_counter() + seconds, 0, time.process_time()
    while time.perf_counter() < end:
        env.step(hold)
        steps += 1
    results.put((steps, time.process_time() - cpu_start))
    env.close()


def make_policy(batch: int, denoising_steps: int, policy_args: list[str]):
    """The `diffusion_head_wrist` preset's policy with random weights, on the GPU where there is one, and a random
    observation batch for it."""
    import draccus
    import lerobot.policies  # noqa: F401  (registers the policy types)
    import torch
    from lerobot.configs.train import TrainPipelineConfig
    from lerobot.configs.types import FeatureType, PolicyFeature
    from lerobot.policies.diffusion.modeling_diffusion import DiffusionPolicy

    import lerobot_env_tavis  # noqa: F401  (registers the env type)
    from lerobot_tavis import canonical
    from lerobot_tavis.policy_configs import preset_path

    device = "cuda" if torch.cuda.is_available() else "cpu"
    args = [f"--policy.device={device}", "--policy.noise_scheduler_type=DDIM",
            f"--policy.num_inference_steps={denoising_steps}", *policy_args]
    config = draccus.parse(TrainPipelineConfig, config_path=str(preset_path("diffusion_head_wrist")), args=args).policy
    config.output_features = {"action": PolicyFeature(type=FeatureType.ACTION, shape=(canonical.ACTION_DIM,))}
    policy = DiffusionPolicy(config).to(device).eval()
    observation = {key: torch.rand(batch, *feature.shape, device=device)
                   for key, feature in config.input_features.items()}
    return policy, observation


def _chunk_ms(policy, observation, seconds: float) -> float:
    """Milliseconds per generated action chunk, select_action called for `seconds` (GPU work waited for) after one
    untimed chunk (the first builds what is built lazily: cuDNN's plans, a compiled model's graphs)."""
    import torch

    cuda = observation["observation.state"].is_cuda
    autocast = torch.autocast("cuda") if cuda else contextlib.nullcontext()

    def one_chunk() -> None:
        for _ in range(policy.config.n_action_steps):  # the first call of each round generates the chunk
            policy.select_action(observation)
        if cuda:
            torch.cuda.synchronize()

    policy.reset()
    with torch.inference_mode(), autocast:
        one_chunk()
        chunks, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds:
            one_chunk()
            chunks += 1
    return 1000 * (time.perf_counter() - start) / chunks


def measure(processes: int, render: bool, seconds: float, camera_mode: str, size: tuple[int, int],
            policy=None) -> dict:
    """Steps per second over `processes` concurrent envs and the CPU cores they used; with `policy` (a policy and
    its observation batch), also its milliseconds per action chunk meanwhile."""
    ctx = mp.get_context("spawn")
    ready, results = ctx.Barrier(processes + 1), ctx.Queue()
    workers = [ctx.Process(target=_step_for, args=(seconds, render, camera_mode, size, ready, results))
               for _ in range(processes)]
    for worker in workers:
        worker.start()
    ready.wait()
    chunk_ms = _chunk_ms(*policy, seconds) if policy else None
    totals = [results.get() for _ in workers]
    for worker in workers:
        worker.join()
    return {"processes": processes, "render": render, "steps_per_s": sum(t[0] for t in totals) / seconds,
            "cpu_cores": sum(t[1] for t in totals) / seconds, "chunk_ms": chunk_ms}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=12.0)
    parser.add_argument("--render", type=int, nargs="*", default=[1, 16, 48, 96], help="process counts, rendering")
    parser.add_argument("--no-render", type=int, nargs="*", default=[96], help="process counts, no camera")
    parser.add_argument("--camera-mode", default="head_wrist")
    parser.add_argument("--image-size", default="240x320", help="HxW of each camera image")
    parser.add_argument("--policy-batch", type=int, default=0, help="envs per action chunk of the policy (0: none)")
    parser.add_argument("--denoising-steps", type=int, default=10, help="DDIM steps per chunk")
    parser.add_argument("--policy-arg", action="append", default=[], help="a lerobot-train option for the policy")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.image_size.split("x"))
    policy = make_policy(args.policy_batch, args.denoising_steps, args.policy_arg) if args.policy_batch else None
    counts = [(n, True) for n in args.render] + [(n, False) for n in args.no_render]
    if policy:
        counts.insert(0, (0, False))  # the policy alone
    cpus = len(os.sched_getaffinity(0))  # those this process may use (taskset, a container's cpuset)
    print(f"{args.camera_mode} at {args.image_size}, {cpus} CPUs, MUJOCO_GL={os.environ['MUJOCO_GL']}"
          + (f", policy chunks for {args.policy_batch} envs, DDIM-{args.denoising_steps}" if policy else ""))
    print("\n| processes | cameras rendered | env steps/s (all processes) | CPU cores busy | policy chunk (ms) |"
          "\n|---|---|---|---|---|")
    for processes, render in counts:
        row = measure(processes, render, args.seconds, args.camera_mode, size, policy)
        chunk = "-" if row["chunk_ms"] is None else f"{row['chunk_ms']:.0f}"
        print(f"| {processes} | {'yes' if render else 'none'} | {row['steps_per_s']:,.0f} | {row['cpu_cores']:.1f} "
              f"| {chunk} |", flush=True)


if __name__ == "__main__":
    main()
