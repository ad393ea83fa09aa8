"""benchmarks/train_throughput.py `scale`: its table from the runs measured (speed-up over one GPU, utilisation,
time to the sample budget), the utilisation window, and its help. The runs themselves need GPUs (docs/training.md,
"Training at scale"); tests/dataset_tools/test_frame_cache.py trains through the same accelerate command on CPU."""

import json
import os
import subprocess
import sys
from pathlib import Path

BENCHMARK = Path(__file__).resolve().parents[1] / "benchmarks" / "train_throughput.py"


def _run(setting, gpus, cache, wall_sps, utilisation, batch=128):
    return {"setting": setting, "gpus": gpus, "cache": cache, "wall_sps": wall_sps, "sps": wall_sps,
            "gpu_utilisation": utilisation, "batch_per_gpu": batch, "video_backend": "torchcodec", "update": 0.05,
            "data": 0.01, "device": "cuda"}


def test_the_scale_table_compares_each_run_with_decoded_frames_on_one_gpu_at_the_same_batch(benchmark_script,
                                                                                            tmp_path):
    throughput = benchmark_script("train_throughput")
    runs = [_run("act", 1, "off", 800.0, {"0": 40.0}), _run("act", 1, "uint8", 2000.0, {"0": 90.0}),
            _run("act", 2, "uint8", 3800.0, {"0": 80.0, "1": 70.0}), _run("act", 4, "float32", 2400.0, {}),
            _run("act", 1, "off", 1000.0, {"0": 50.0}, batch=256), _run("act", 1, "uint8", 2500.0, {}, batch=256)]
    (tmp_path / "scale").mkdir()
    for index, run in enumerate(runs):
        (tmp_path / "scale" / f"{index}.json").write_text(json.dumps(run))
    throughput.write_scale_report(tmp_path, budget=409_600, episodes=24)
    rows = [line.split(" | ") for line in (tmp_path / "scale.md").read_text().splitlines() if line.startswith("| act")]
    table = {(row[1], row[2], row[3]): row for row in rows}
    assert [row[1:4] for row in rows] == [["1", "decoded (torchcodec)", "128"], ["1", "cache, uint8", "128"],
                                          ["2", "cache, uint8", "128"], ["4", "cache, float32 from workers", "128"],
                                          ["1", "decoded (torchcodec)", "256"], ["1", "cache, uint8", "256"]]
    assert table["2", "cache, uint8", "128"][5] == "4.75"  # 3800 / 800
    assert table["2", "cache, uint8", "128"][7] == "75; 70"  # mean over both GPUs; the lower one
    assert table["2", "cache, uint8", "128"][10] == "1.8 |"  # 409 600 samples at 3800 samples/s, minutes
    assert table["4", "cache, float32 from workers", "128"][5] == "3.00"
    assert table["4", "cache, float32 from workers", "128"][7] == "n/a"
    assert table["1", "cache, uint8", "256"][5] == "2.50"  # against batch 256 decoded: 2500 / 1000
    assert len(json.loads((tmp_path / "scale.json").read_text())["runs"]) == 6
    assert "not a measurement" not in (tmp_path / "scale.md").read_text()


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
    assert "--warm-up" in result.stdout and "float32" in result.stdout


def test_scale_refuses_an_unknown_setting_in_one_line():
    env = {**os.environ, "PYTHONPATH": str(BENCHMARK.parents[1])}
    result = subprocess.run([sys.executable, str(BENCHMARK), "scale", "--work", "/nonexistent", "--settings",
                             "act_nonsense"], capture_output=True, text=True, env=env, timeout=120)
    assert result.returncode == 2
    assert result.stderr.splitlines()[-1].startswith("train_throughput.py: error: --settings: unknown preset "
                                                     "'act_nonsense'; presets: ")
