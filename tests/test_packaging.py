import re
import shutil
import subprocess
import sys
import threading
import zipfile
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_wheel_carries_every_asset(tmp_path):
    source = tmp_path / "src"
    source.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, source / name)
    for package in ("lerobot_tavis", "lerobot_env_tavis"):
        shutil.copytree(ROOT / package, source / package, ignore=shutil.ignore_patterns("__pycache__"))
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(source), "--no-deps", "--no-build-isolation", "-q",
                    "-w", str(tmp_path / "dist")], check=True, capture_output=True)
    (wheel,) = (tmp_path / "dist").glob("*.whl")
    packed = set(zipfile.ZipFile(wheel).namelist())
    assets = [p.relative_to(ROOT).as_posix() for p in (ROOT / "lerobot_tavis" / "assets").rglob("*") if p.is_file()]
    assert len(assets) > 50
    assert [a for a in assets if a not in packed] == []
    size_mb = sum(info.file_size for info in zipfile.ZipFile(wheel).infolist() if "/assets/" in info.filename) / 1e6
    assert size_mb <= 25.0


def _make_setup(tmp_path, *settings: str) -> tuple[subprocess.CompletedProcess, list[str]]:
    """`make setup` with a stand-in `python` in a scratch venv that logs its arguments and fails where it is asked
    for the PyTorch CPU index: (the result, the logged calls)."""
    venv = tmp_path / "venv"
    (venv / "bin").mkdir(parents=True)
    log = tmp_path / "calls"
    python = venv / "bin" / "python"
    python.write_text(f'#!/bin/sh\necho "$*" >> {log}\ncase "$*" in *--index-url*) exit 1;; esac\n')
    python.chmod(0o755)
    result = subprocess.run(["make", "--no-print-directory", "setup", f"VENV={venv}", *settings], cwd=ROOT,
                            capture_output=True, text=True, timeout=120)
    return result, log.read_text().splitlines()


def test_setup_with_cpu_installs_torch_from_the_cpu_index_before_the_package(tmp_path):
    result, calls = _make_setup(tmp_path)
    assert result.returncode == 0 and not [call for call in calls if "--index-url" in call]
    assert calls[-1] == f"-m uv pip install --python {tmp_path}/venv/bin/python -e .[dev]"
    (tmp_path / "index" / "whl" / "cpu" / "torch").mkdir(parents=True)
    (tmp_path / "index" / "whl" / "cpu" / "torch" / "index.html").write_text("<html></html>")
    serve = partial(SimpleHTTPRequestHandler, directory=str(tmp_path / "index"))
    with ThreadingHTTPServer(("127.0.0.1", 0), serve) as server:  # a reachable stand-in for PyTorch's index
        threading.Thread(target=server.serve_forever, daemon=True).start()
        index = f"http://127.0.0.1:{server.server_address[1]}/whl/cpu"
        result, calls = _make_setup(tmp_path / "cpu", "CPU=1", f"TORCH_CPU_INDEX={index}")
        server.shutdown()
    assert result.returncode != 0
    assert calls[-1].startswith(f"-m pip install --index-url {index} torch>=2.7,<2.12 ")
    assert "CPU=1: PyTorch's CPU wheels could not be installed" in result.stdout + result.stderr
    assert not (tmp_path / "cpu" / "venv" / ".installed").exists()


TEXT_SUFFIXES = {".py", ".md", ".sh", ".toml", ".txt", ".cfg", ".yaml", ".yml"}
# Files that exist only outside the repository; the facts the project needs from them are in docs/reference.md.
NOT_SHIPPED = ("reference" + " §", "robots_objects" + "_physics", "tavis_benchmark" + ".md", "DESIGN" + ".md")


def _project_texts():
    for top in ("lerobot_tavis", "lerobot_env_tavis", "tests", "benchmarks", "tools", "docs"):
        for path in sorted((ROOT / top).rglob("*")):
            if path.suffix in TEXT_SUFFIXES and "__pycache__" not in path.parts:
                yield path
    for name in ("README.md", "Makefile", "pyproject.toml"):
        yield ROOT / name


def test_citations_name_only_files_that_ship():
    """Every "§" cites a numbered section of docs/reference.md that exists; no file cites notes that do not ship."""
    reference = (ROOT / "docs" / "reference.md").read_text()
    sections = set(re.findall(r"^## §(\d+) ", reference, flags=re.MULTILINE))
    assert sections == {str(n) for n in range(1, len(sections) + 1)}
    bad = []
    for path in _project_texts():
        text = path.read_text(errors="replace")
        bad += [f"{path.relative_to(ROOT)}: {name}" for name in NOT_SHIPPED if name in text]
        if path.name == "reference.md" and path.parent.name == "docs":
            continue
        for match in re.finditer(r"§(\d+)", text):
            cited_here = "reference.md" in text[max(0, match.start() - 40):match.start()]
            if not cited_here or match.group(1) not in sections:
                bad.append(f"{path.relative_to(ROOT)}: {text[max(0, match.start() - 40):match.end()]!r}")
    assert bad == []
