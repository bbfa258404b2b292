"""Every entry point offers the same backends and shows each one's device the
same way: `mmvk query`, `mmvk crowd`, mmvk.backends(), mmvk.Search and
mmvk.Crowd all make their backends in one place (host/crowd/backends/host_backends.hpp),
and a backend reports its own device text (SearchBackend::device())."""
import json
import os
import re
import subprocess

import numpy as np
import pytest

import mmvk
from conftest import CMU131, vulkan_required

# One backend of each kind: the one-thread oracle, the pooled CPU ones and,
# when built, a Vulkan one (lavapipe in CI).
DEVICE_BACKENDS = ["reference", "fast-box", "clusters", "vulkan-brute"]


def help_backends(cli, command):
    """The backend names a command's --help lists, in order."""
    text = subprocess.run([str(cli), command, "--help"], check=True, capture_output=True, text=True).stdout
    heading = re.search(r"^backends.*:$", text, re.MULTILINE)
    assert heading, text
    section = text[heading.end():].split("\n")[1:]
    names = []
    for line in section:
        match = re.match(r"^  ([a-z][a-z-]*)  ", line)
        if not match:
            break
        names.append(match.group(1))
    return names


def test_every_entry_point_lists_the_same_backends(cli):
    listed = mmvk.backends()
    assert listed[:5] == ["reference", "fast-brute", "fast-box", "clusters", "clusters-nprobe"]
    assert help_backends(cli, "query") == listed
    # The crowd's "auto" is a rule over the others, listed first.
    assert help_backends(cli, "crowd") == ["auto"] + listed


def query_device(cli, db_file, db, backend, tmp_path):
    q = tmp_path / "q.f32"
    np.ascontiguousarray(db.features[:4], dtype="<f4").tofile(q)
    run = subprocess.run([str(cli), "query", str(db_file), "--queries", str(q), "--normalized", "--backend", backend,
                          "--out", str(tmp_path / "out.tsv")], check=True, capture_output=True, text=True)
    match = re.search(r"backend " + re.escape(backend) + r" on (.*), [0-9.]+ ms", run.stderr)
    assert match, run.stderr
    return match.group(1)


def crowd_device(cli, backend, tmp_path):
    out = tmp_path / "crowd.json"
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"))
    subprocess.run([str(cli), "crowd", "--data", str(CMU131), "--agents", "3", "--seconds", "0.2", "--backend", backend,
                    "--summary", str(out)], check=True, capture_output=True, env=env)
    return json.loads(out.read_text())["device"]


@pytest.mark.parametrize("backend", DEVICE_BACKENDS)
def test_every_entry_point_shows_the_same_device(backend, db, db_file, cli, tmp_path):
    if backend not in mmvk.backends():
        pytest.skip(f"{backend} is not built")
    try:
        search = mmvk.Search(db, backend)
    except ValueError as error:
        # Only a missing Vulkan device may skip, and not in CI.
        if backend.startswith("vulkan") and not vulkan_required():
            pytest.skip(f"no Vulkan device: {error}")
        raise
    device = search.device
    if backend == "reference":
        assert device == "cpu, 1 thread"
    elif backend.startswith("vulkan"):
        assert re.search(r" \(Vulkan device [0-9]+, [^)]+\)$", device), device
    else:
        assert re.fullmatch(r"cpu, ([2-9]|[1-9][0-9]+) threads|cpu, 1 thread", device), device
    assert mmvk.Crowd(db, agents=3, backend=backend).device == device
    assert query_device(cli, db_file, db, backend, tmp_path) == device
    assert crowd_device(cli, backend, tmp_path) == device
