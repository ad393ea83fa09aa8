"""`process.without_realtime_priority`: an AV1 encoder opened inside it leaves every thread at normal scheduling."""

import json
import os
import subprocess
import sys

import pytest

# In a fresh process (the suite's own processes run inside the guard, tests/conftest.py): open and use an SVT-AV1
# encoder in a thread without the guard, then in a thread inside it, and report each thread's scheduling policy.
SCRIPT = """
import json, os, threading
import av, numpy as np
from lerobot_tavis.process import _CAP_SYS_NICE, _set_effective_capability, without_realtime_priority

def encode_and_report(policies, name):
    container = av.open(os.devnull, "w", format="mp4")
    stream = container.add_stream("libsvtav1", rate=10)
    stream.width, stream.height, stream.pix_fmt = 64, 48, "yuv420p"
    for value in range(0, 250, 50):
        frame = av.VideoFrame.from_ndarray(np.full((48, 64, 3), value, np.uint8), format="rgb24")
        for packet in stream.encode(frame):
            container.mux(packet)
    for packet in stream.encode():
        container.mux(packet)
    policies[name] = os.sched_getscheduler(0)
    container.close()

def in_a_thread(name):
    thread = threading.Thread(target=encode_and_report, args=(policies, name))
    thread.start()
    thread.join()

policies = {}
_set_effective_capability(_CAP_SYS_NICE, True)  # effective wherever it is permitted (root)
capable = _set_effective_capability(_CAP_SYS_NICE, True)
in_a_thread("unguarded")
with without_realtime_priority():
    in_a_thread("guarded")
print(json.dumps({"capable": capable, **policies, "restored": _set_effective_capability(_CAP_SYS_NICE, True),
                  "main": os.sched_getscheduler(0)}))
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux scheduling and capabilities")
def test_an_av1_encoder_cannot_make_a_guarded_thread_real_time():
    """Unguarded, SVT-AV1 moves its thread to SCHED_FIFO where the process may (root, as on CI); guarded it
    cannot, and the guard gives the capability back at its end."""
    done = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=120, check=True)
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report["guarded"] == os.SCHED_OTHER and report["main"] == os.SCHED_OTHER
    assert report["unguarded"] == (os.SCHED_FIFO if report["capable"] else os.SCHED_OTHER)
    assert report["restored"] == report["capable"]
