"""benchmarks/train_throughput.py `scale`: its table from the runs measured (speed-up over one GPU, utilisation,
time to the sample budget), the utilisation window, and its help. The runs themselves need GPUs (docs/training.md,
"Training at scale"); tests/dataset_tools/test_frame_cache.py trains through the same accelerate command on CPU."""

import json
import os
import subprocess
import sys
from pathlib import Path

BENCHMARK = Path(__file__).resolve().parents[1] / "benchmarks" / "train_throughput.py"


def _run(setting, gpus, cache, wall_sps, utilisation):
    return {"setting": setting, "gpus": gpus, "cache": cache, "wall_sps": wall_sps, "sps": wall_sps,
            "gpu_utilisation": utilisation, "batch_per_gpu": 128, "video_backend": "torchcodec", "update": 0.05,
            "data": 0.01}


def test_the_scale_table_compares_each_gpu_count_with_one_gpu_of_the_same_frames(benchmark_script, tmp_path):
    throughput = benchmark_script("train_throughput")
    runs = [_run("act", 1, True, 2000.0, {"0": 90.0}), _run("act", 2, True, 3800.0, {"0": 80.0, "1": 70.0}),
            _run("act", 1, False, 800.0, {"0": 40.0}), _run("act", 4, False, 2400.0, {})]
    (tmp_path / "scale").mkdir()
    for index, run in enumerate(runs):
        (tmp_path / "scale" / f"{index}.json").write_text(json.dumps(run))
    throughput.write_scale_report(tmp_path, budget=409_600, episodes=24)
    rows = [line.split(" | ") for line in (tmp_path / "scale.md").read_text().splitlines() if line.startswith("| act")]
    table = {(row[1], row[2]): row for row in rows}
    assert table["2", "frame cache"][5] == "1.90"  # 3800 / 2000
    assert table["2", "frame cache"][7] == "75; 70"  # mean over both GPUs; the lower one
    assert table["2", "frame cache"][10] == "1.8 |"  # 409 600 samples at 3800 samples/s, minutes
    assert table["4", "decoded (torchcodec)"][5] == "3.00" and table["4", "decoded (torchcodec)"][7] == "n/a"
    assert len(json.loads((tmp_path / "scale.json").read_text())["runs"]) == 4


def test_utilisation_counts_only_the_samples_inside_the_window(benchmark_script):
    throughput = benchmark_script("train_throughput")
    sampler = throughput.GpuUtilisation(["0", "1"])
    sampler.samples = [(1.0, "0", 10.0), (2.0, "0", 90.0), (3.0, "0", 70.0), (2.5, "1", 50.0), (9.0, "1", 0.0)]
    assert sampler.means(2.0, 3.0) == {"0": 80.0, "1": 50.0}


def test_help_names_the_scale_stage():
    env = {**os.environ, "PYTHONPATH": str(BENCHMARK.parents[1])}
    result = subprocess.run([sys.executable, str(BENCHMARK), "--help"], capture_output=True, text=True, env=env,
                            check=True, timeout=120)
    assert "scale" in result.stdout and "--gpus" in result.stdout and "--cache" in result.stdout
