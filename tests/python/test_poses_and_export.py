"""The displayed pose out of mmvk.Crowd and into files: forward kinematics of
the exposed roots and local rotations gives joint_positions (foot IK on, 30
and 60 Hz); a BVH export rebuilt by `mmvk build` and read by the short
reader below gives back the displayed joints within 1 mm; the glTF export
passes the Khronos glTF-Validator; bad export options are refused before
the run, naming the option."""
import json
import os
import pathlib
import shutil
import struct
import subprocess

import numpy as np
import pytest

import mmvk
from conftest import CMU131, REPO

# The pinned validator (tools/install_gltf_validator.sh puts it here).
GLTF_VALIDATOR = REPO / ".cache" / "gltf-validator" / "node_modules" / "gltf-validator"


def qmul(a, b):
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz], -1)


def qrot(q, v):
    u, w = q[..., :3], q[..., 3:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def fk(parents, rotations, translations, root_positions, root_rotations):
    """World joint positions [n x joints x 3] of local (x, y, z, w) rotations and
    translations [n x joints x 4|3] under roots [n x 3], [n x 4], in float64."""
    rotations, translations = rotations.astype(np.float64), translations.astype(np.float64)
    world_q, world_p = np.zeros(rotations.shape), np.zeros(translations.shape)
    for j, p in enumerate(parents):
        pq = root_rotations.astype(np.float64) if p < 0 else world_q[:, p]
        pp = root_positions.astype(np.float64) if p < 0 else world_p[:, p]
        world_q[:, j] = qmul(pq, rotations[:, j])
        world_p[:, j] = pp + qrot(pq, translations[:, j])
    return world_p


def yaw_quats(yaws):
    yaws = np.asarray(yaws, np.float64)
    return np.stack([np.zeros_like(yaws), np.sin(yaws / 2), np.zeros_like(yaws), np.cos(yaws / 2)], -1)


@pytest.mark.parametrize("rate", [30.0, 60.0])
def test_forward_kinematics_of_the_exposed_pose_gives_joint_positions(db, rate):
    crowd = mmvk.Crowd(db, agents=12, rate=rate, backend="fast-box", seed=4)
    skeleton = crowd.skeleton
    assert skeleton["names"] == db.animation.joint_names
    assert np.array_equal(skeleton["parents"], db.animation.parents)
    worst, locked = 0.0, 0
    for _ in range(int(rate * 2)):
        crowd.step()
        rotations = crowd.local_rotations
        assert np.allclose(np.linalg.norm(rotations, axis=-1), 1.0, atol=1e-5)
        world = fk(skeleton["parents"], rotations, crowd.local_translations, crowd.root_positions,
                   crowd.root_rotations)
        worst = max(worst, float(np.abs(world - crowd.joint_positions).max()))
        locked += int(crowd.foot_locked.sum())
    assert locked > 0, "foot IK held no foot: the test would not see IK's changes"
    assert worst < 1e-4
    # The roots' rotations are the yaws the crowd reports.
    assert np.allclose(crowd.root_rotations, yaw_quats(crowd.root_yaws), atol=1e-6)


def record(db, agents, rate, seconds, record_poses):
    """A crowd stepped for `seconds`, and the displayed joints of its first
    record_poses characters per tick [ticks x record_poses x joints x 3]."""
    crowd = mmvk.Crowd(db, agents=agents, rate=rate, backend="fast-box", seed=2, record_poses=record_poses)
    shown = []
    for _ in range(int(rate * seconds)):
        crowd.step()
        shown.append(crowd.joint_positions[:record_poses])
    return crowd, np.stack(shown)


def read_bvh(path):
    """The joint names, parents and world joint positions [frames x joints x 3]
    (the file's units) of a BVH file: channels in file order, rotations
    intrinsic (R = R1 * R2 * R3), position channels replacing the OFFSET."""
    tokens = path.read_text().split()
    names, parents, offsets, channels, stack, i = [], [], [], [], [], 1
    while tokens[i] != "MOTION":
        word = tokens[i]
        if word in ("ROOT", "JOINT"):
            names.append(tokens[i + 1])
            parents.append(stack[-1] if stack else -1)
            i += 2
        elif word == "End":
            depth, i = 0, i + 2
            while True:
                depth += {"{": 1, "}": -1}.get(tokens[i], 0)
                i += 1
                if depth == 0:
                    break
        elif word == "{":
            stack.append(len(names) - 1)
            i += 1
        elif word == "}":
            stack.pop()
            i += 1
        elif word == "OFFSET":
            offsets.append([float(v) for v in tokens[i + 1:i + 4]])
            i += 4
        elif word == "CHANNELS":
            n = int(tokens[i + 1])
            channels.append(tokens[i + 2:i + 2 + n])
            i += 2 + n
    frames = int(tokens[i + 2])
    values = np.array(tokens[i + 6:], np.float64).reshape(frames, -1)
    rotations = np.zeros((frames, len(names), 4))
    translations = np.zeros((frames, len(names), 3))
    column = 0
    for j, joint_channels in enumerate(channels):
        q = np.tile([0.0, 0.0, 0.0, 1.0], (frames, 1))
        t = np.tile(offsets[j], (frames, 1))
        for name in joint_channels:
            axis = "XYZ".index(name[0])
            v = values[:, column]
            column += 1
            if name.endswith("position"):
                t[:, axis] = v
            else:
                half = np.radians(v) / 2
                r = np.zeros((frames, 4))
                r[:, axis], r[:, 3] = np.sin(half), np.cos(half)
                q = qmul(q, r)
        rotations[:, j], translations[:, j] = q, t
    roots = np.zeros((frames, 3))
    world = fk(parents, rotations, translations, roots, yaw_quats(np.zeros(frames)))
    return names, parents, world


def test_bvh_export_rebuilt_by_mmvk_build_gives_the_displayed_joints(db, cli, tmp_path):
    crowd, shown = record(db, agents=8, rate=30.0, seconds=3.0, record_poses=3)
    out = tmp_path / "bvh"
    crowd.write_bvh(out)
    files = sorted(out.glob("*.bvh"))
    assert [f.name for f in files] == ["agent_0000.bvh", "agent_0001.bvh", "agent_0002.bvh"]
    names = db.animation.joint_names

    # The short reader: the file's own joints, in centimetres.
    for b, f in enumerate(files):
        file_names, _, world = read_bvh(f)
        order = [file_names.index(n) for n in names]
        assert np.abs(world[:, order] / 100.0 - shown[:, b]).max() < 1e-3

    # `mmvk build` of the folder, at the tick rate: each clip's frames placed
    # by its stored roots are the displayed joints.
    mmdb = tmp_path / "export.mmdb"
    subprocess.run([str(cli), "build", str(out), "-o", str(mmdb), "--fps", "30"], check=True, capture_output=True)
    rebuilt = mmvk.Database.load(mmdb)
    a = rebuilt.animation
    order = [a.joint_names.index(n) for n in names]
    checked = 0
    for clip in rebuilt.clips:
        b = [f.name for f in files].index(pathlib.Path(clip["source"]).name)
        frames = slice(clip["first_frame"], clip["first_frame"] + clip["frame_count"])
        translations = np.tile(a.rest_offsets, (clip["frame_count"], 1, 1))
        translations[:, a.translated_joints] = a.translations[frames]
        world = fk(a.parents, a.rotations[frames], translations, a.root_positions[frames],
                   yaw_quats(a.root_yaws[frames]))
        assert clip["frame_count"] == len(shown)
        assert np.abs(world[:, order] - shown[:, b]).max() < 1e-3, clip["name"]
        checked += 1
    assert checked == 3


def read_glb(path):
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<III", data, 0)
    assert (magic, version, length) == (0x46546C67, 2, len(data))
    json_length, = struct.unpack_from("<I", data, 12)
    gltf = json.loads(data[20:20 + json_length])
    return gltf, data[28 + json_length:]


def test_gltf_export_animates_the_displayed_joints(db, tmp_path):
    crowd, shown = record(db, agents=6, rate=60.0, seconds=1.0, record_poses=2)
    path = tmp_path / "crowd.glb"
    crowd.write_gltf(path)
    gltf, binary = read_glb(path)

    def accessor(index):
        a = gltf["accessors"][index]
        view = gltf["bufferViews"][a["bufferView"]]
        width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}[a["type"]]
        return np.frombuffer(binary, np.float32, a["count"] * width, view["byteOffset"]).reshape(a["count"], width)

    ticks = len(shown)
    animation = gltf["animations"][0]
    tracks = {}
    for channel in animation["channels"]:
        sampler = animation["samplers"][channel["sampler"]]
        times = accessor(sampler["input"])[:, 0]
        assert np.allclose(times, np.arange(ticks) / 60.0)
        tracks[(channel["target"]["node"], channel["target"]["path"])] = accessor(sampler["output"])
    names = db.animation.joint_names
    for b, skin in enumerate(gltf["skins"]):
        root = skin["skeleton"]
        joints = skin["joints"]
        assert [gltf["nodes"][n]["name"] for n in joints] == names
        translations = np.stack([tracks.get((n, "translation"), np.tile(gltf["nodes"][n]["translation"], (ticks, 1)))
                                 for n in joints], 1)
        rotations = np.stack([tracks[(n, "rotation")] for n in joints], 1)
        world = fk(db.animation.parents, rotations, translations, tracks[(root, "translation")],
                   tracks[(root, "rotation")])
        assert np.abs(world - shown[:, b]).max() < 1e-4


def validator_required():
    return os.environ.get("MMVK_REQUIRE_GLTF_VALIDATOR", "") not in ("", "0")


def test_gltf_export_of_20_characters_passes_the_khronos_validator(cli, tmp_path):
    node = shutil.which("node") or shutil.which("nodejs")
    if node is None or not (GLTF_VALIDATOR / "package.json").exists():
        why = f"node and the gltf-validator package in {GLTF_VALIDATOR} (tools/install_gltf_validator.sh)"
        if validator_required():
            pytest.fail(f"MMVK_REQUIRE_GLTF_VALIDATOR=1 and no {why}")
        pytest.skip(f"needs {why}")
    path = tmp_path / "crowd.glb"
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"))
    subprocess.run([str(cli), "crowd", "--data", str(CMU131), "--agents", "20", "--seconds", "2", "--backend",
                    "fast-box", "--gltf", str(path), "--export-agents", "20"], check=True, capture_output=True, env=env)
    script = ("const v = require(process.argv[1]); const fs = require('fs');"
              "v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[2])), {maxIssues: 0})"
              ".then(r => console.log(JSON.stringify(r)), e => { console.error(e); process.exit(2); });")
    result = subprocess.run([node, "-e", script, str(GLTF_VALIDATOR), str(path)], check=True, capture_output=True,
                            text=True)
    report = json.loads(result.stdout)
    issues = report["issues"]
    errors = [m for m in issues["messages"] if m["severity"] == 0]
    assert issues["numErrors"] == 0, errors[:5]
    assert report["info"]["animationCount"] == 1
    assert len(read_glb(path)[0]["skins"]) == 20


@pytest.mark.parametrize("args, message", [
    (["--bvh", "{tmp}/bvh", "--export-agents", "9"], "--export-agents 9 must be in [1, 8]"),
    (["--bvh", "{tmp}/file/bvh"], "--bvh"),
    (["--bvh", "{tmp}/missing/bvh"], "--bvh"),
    (["--gltf", "{tmp}/crowd.gltf"], "--gltf"),
    (["--gltf", "{tmp}/missing/crowd.glb"], "--gltf"),
    (["--export-agents", "2"], "--export-agents needs --bvh DIR or --gltf FILE.glb"),
    (["--gltf", "{tmp}/crowd.glb", "--export-agents", "1", "--seconds", "100000", "--rate", "10"],
     "--gltf: 1000000 ticks x 1 characters x 31 joints would take * MiB of poses, over the 512 MiB"),
])
def test_bad_export_options_are_refused_before_the_run(cli, tmp_path, args, message):
    (tmp_path / "file").write_text("a file, not a folder")
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"))
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    result = subprocess.run([str(cli), "crowd", "--data", str(CMU131), "--agents", "8", "--backend", "fast-box",
                             "--summary", str(tmp_path / "s.json"), *args],
                            capture_output=True, text=True, env=env)
    assert result.returncode != 0
    assert all(part in result.stderr for part in message.split(" * ")), result.stderr
    assert not (tmp_path / "s.json").exists(), "the run went ahead"


def test_python_export_options_are_checked(db, tmp_path):
    with pytest.raises(ValueError, match="record_poses 7 must be in \\[1, 6\\]"):
        mmvk.Crowd(db, agents=6, record_poses=7)
    crowd = mmvk.Crowd(db, agents=6, backend="fast-box")
    crowd.step()
    with pytest.raises(ValueError, match="record_poses=M"):
        crowd.write_bvh(tmp_path / "bvh")
    crowd = mmvk.Crowd(db, agents=6, backend="fast-box", record_poses=2)
    with pytest.raises(ValueError, match="over the 512 MiB"):
        crowd.run(10_000_000 / 30.0)
    assert crowd.ticks == 0, "the run went ahead"
    crowd.step()
    with pytest.raises(OSError, match="name it .glb"):
        crowd.write_gltf(tmp_path / "crowd.gltf")
