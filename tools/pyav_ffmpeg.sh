#!/usr/bin/env bash
# Expose the FFmpeg shared libraries bundled in PyAV's wheel under their standard names, for torchcodec
# (LeRobot's `--dataset.video_backend=torchcodec`) on a machine without system FFmpeg libraries.
#
#   eval "$(tools/pyav_ffmpeg.sh [DIR])"      # DIR defaults to /tmp/pyav-ffmpeg; prints the export to run
#
# The links point into PyAV's `av.libs` folder, so PyAV and torchcodec load the same files.
set -euo pipefail
dir=${1:-/tmp/pyav-ffmpeg}
libs=$(python3 -c 'import av, pathlib; print(pathlib.Path(av.__file__).parent.parent / "av.libs")')
[ -d "$libs" ] || { echo "pyav_ffmpeg.sh: no bundled FFmpeg in PyAV ($libs missing)" >&2; exit 1; }
mkdir -p "$dir"
for lib in "$libs"/libav*.so.* "$libs"/libsw*.so.*; do
  name=$(basename "$lib")               # e.g. libavcodec-7ee0753d.so.61.19.101
  version=${name#*.so.}
  ln -sfn "$lib" "$dir/${name%%-*}.so.${version%%.*}"   # -> libavcodec.so.61
done
echo "export LD_LIBRARY_PATH=$dir:$libs\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
