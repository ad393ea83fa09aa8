# Two entry points for a fresh machine: `make demo` and `make test`. Both create .venv with Python 3.12 when
# missing and install the package (editable, with its extras) into it, with uv: the same packages from PyPI as pip
# would install, downloaded and unpacked in parallel. Modules are compiled to bytecode when first imported, as
# Python does by default, and kept: the demo and the tests import a small part of what is installed, so compiling
# all of it at install (pip's way) costs more than it saves. An environment that sets PYTHONDONTWRITEBYTECODE would
# have every process compile torch and LeRobot again, so the targets below clear it.

VENV := .venv
STAMP := $(VENV)/.installed
# `make setup CPU=1`: torch and torchvision from PyTorch's CPU-only wheel index first, so that the CUDA libraries
# PyPI's Linux torch depends on (about 3.3 GB of .venv with triton) are never installed; the rest from PyPI.
CPU ?= 0
TORCH_CPU_INDEX := https://download.pytorch.org/whl/cpu
TORCH_CPU_PACKAGES := 'torch>=2.7,<2.12' torchvision
# python3.12 from PATH, else a pyenv-managed 3.12 (pyenv shims exist even when 3.12 is not the active version).
PYTHON ?= $(shell for p in python3.12 $$HOME/.pyenv/versions/3.12*/bin/python3.12; do \
	$$p -c 'import sys; assert sys.version_info[:2] == (3, 12)' 2>/dev/null && { echo $$p; break; }; done)
export MUJOCO_GL ?= egl
export PYTHONDONTWRITEBYTECODE :=

.PHONY: demo test setup system-deps clean

setup: $(STAMP)

$(STAMP): pyproject.toml
	@test -n "$(PYTHON)" || { echo "Python 3.12 not found: install it or pass PYTHON=/path/to/python3.12"; exit 1; }
ifeq ($(CPU),1)
	@$(PYTHON) -c "import urllib.request; urllib.request.urlopen('$(TORCH_CPU_INDEX)/torch/', timeout=30).read(1)" \
		2>/dev/null || { echo "make setup CPU=1: PyTorch's CPU wheel index $(TORCH_CPU_INDEX) cannot be reached" \
			"from here (PyPI has no CPU-only torch for Linux): run make setup without CPU=1 (PyPI's CUDA build runs" \
			"on a CPU as well)"; exit 1; }
endif
	@$(MAKE) --no-print-directory system-deps
	test -x $(VENV)/bin/python || $(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install --upgrade pip uv
ifeq ($(CPU),1)
	$(VENV)/bin/python -m pip install --index-url $(TORCH_CPU_INDEX) $(TORCH_CPU_PACKAGES) \
		|| { echo "CPU=1: PyTorch's CPU wheels could not be installed from $(TORCH_CPU_INDEX) (PyPI has none" \
			"for Linux); without CPU=1, PyPI's CUDA build runs on a CPU as well"; exit 1; }
endif
	$(VENV)/bin/python -m uv pip install --python $(VENV)/bin/python -e '.[dev]'
	touch $(STAMP)

# Headless OpenGL for MuJoCo (EGL on Mesa); Xvfb, the virtual display the viewer's test (and `xvfb-run -a
# tavis view` on a machine without a desktop) opens its window on; FFmpeg's shared libraries, which torchcodec (the
# video decoder LeRobot prefers) loads at run time: without them every dataset load prints torchcodec's failure to
# load before LeRobot falls back to PyAV. torchcodec ships builds for FFmpeg 4 to 8, so the distribution's own
# ffmpeg package fits (Debian 12: FFmpeg 5.1, libavcodec.so.59). Installed only when missing and when apt-get can run.
SYSTEM_PACKAGES := libegl1 libgl1-mesa-dri libopengl0 libgl1 xvfb xauth ffmpeg
system-deps:
	@if ldconfig -p | grep -q 'libEGL.so.1' && ldconfig -p | grep -q 'libOpenGL.so.0\|libGL.so.1' \
		&& ls /usr/lib/*/dri/swrast_dri.so >/dev/null 2>&1 && command -v Xvfb >/dev/null \
		&& ldconfig -p | grep -q 'libavcodec.so.[0-9]'; then :; \
	elif command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ]; then \
		{ apt-get update -qq && apt-get install -y -qq --no-install-recommends $(SYSTEM_PACKAGES); } \
			|| echo "warning: apt-get could not install the OpenGL libraries, Xvfb or FFmpeg"; \
	else echo "warning: EGL/Mesa libraries, Xvfb or FFmpeg's libraries not found (Debian: apt-get install" \
		"$(SYSTEM_PACKAGES))"; fi

demo: $(STAMP)
	$(VENV)/bin/tavis demo --out outputs/demo

test: $(STAMP)
	$(VENV)/bin/python -m pytest -n auto --dist loadfile --no-loadscope-reorder -q

clean:
	rm -rf $(VENV) outputs .pytest_cache
