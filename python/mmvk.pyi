# Type stubs of the mmvk extension module (python/src). Shapes and units are
# in the docstrings; docs/python.md describes the module.
import os
from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, os.PathLike[str]]
FloatArray = npt.NDArray[np.float32]
IntArray = npt.NDArray[np.integer]

def backends() -> list[str]:
    """The search backends by name (CPU ones, then vulkan-* when built with Vulkan)."""

def build(source: Union[PathLike, Mapping[str, Any]], schema: Union[None, PathLike, Mapping[str, Any]] = None,
          **manifest_fields: Any) -> Database:
    """Builds a database from a manifest file, a folder of motion files (BVH, FBX, glTF, COLLADA), one such
    file or a manifest dict; manifest_fields (fps=30, mirror=True, edge_rule='extrapolate', ...) are set over
    the source's fields."""

class Animation:
    """The skeleton and per-frame poses, root and contacts of a Database (read-only views)."""
    @property
    def joint_names(self) -> list[str]: ...
    @property
    def parents(self) -> npt.NDArray[np.int32]:
        """[joints], -1 for the root."""
    @property
    def rest_offsets(self) -> FloatArray:
        """[joints x 3] metres."""
    @property
    def rotations(self) -> FloatArray:
        """[frames x joints x 4] unit quaternions (x, y, z, w), character space for the hips."""
    @property
    def translated_joints(self) -> npt.NDArray[np.uint32]:
        """[T] joints whose translation varies."""
    @property
    def translations(self) -> FloatArray:
        """[frames x T x 3] metres."""
    @property
    def root_positions(self) -> FloatArray:
        """[frames x 3] metres, y = 0."""
    @property
    def root_yaws(self) -> FloatArray:
        """[frames] radians about +Y, 0 faces +Z."""
    @property
    def contacts(self) -> npt.NDArray[np.uint8]:
        """[frames] FootContact bits: 1 left, 2 right, 4 left heel, 8 left toe, 16 right heel, 32 right toe."""
    @property
    def contact_joints(self) -> tuple[int, int]: ...

class Database:
    """A motion matching database (immutable)."""
    @staticmethod
    def load(path: PathLike) -> Database:
        """Loads an .mmdb file; OSError when unreadable, ValueError when invalid."""
    def save(self, path: PathLike) -> None:
        """Writes an .mmdb file atomically; OSError on failure."""
    @property
    def frame_count(self) -> int: ...
    @property
    def dims(self) -> int: ...
    @property
    def fps(self) -> float: ...
    def __len__(self) -> int: ...
    @property
    def features(self) -> FloatArray:
        """[frames x dims] normalized, a read-only view of the database's memory."""
    @property
    def frame_flags(self) -> npt.NDArray[np.uint32]:
        """[frames]: 1 do_not_use, 2 block_transition, 4 edge_excluded."""
    @property
    def frame_tags(self) -> npt.NDArray[np.uint64]:
        """[frames] tag bit masks (bit t = tags[t])."""
    @property
    def frame_clip(self) -> npt.NDArray[np.uint32]:
        """[frames] index into clips."""
    @property
    def tags(self) -> list[str]: ...
    @property
    def channels(self) -> list[dict[str, Any]]:
        """name, kind, offset, dims, weight, normalization, bone, second_bone, offsets_seconds."""
    @property
    def clips(self) -> list[dict[str, Any]]:
        """name, source, tags, loop, mirrored, cost_multiplier, cost_bias, first_frame, frame_count."""
    @property
    def dim_names(self) -> list[str]: ...
    @property
    def schema_json(self) -> str: ...
    @property
    def content_hash(self) -> int: ...
    @property
    def animation(self) -> Optional[Animation]: ...
    def raw(self, features: FloatArray) -> FloatArray:
        """Normalized rows [B x dims] (or [dims]) back to raw values."""
    def normalize(self, raw: FloatArray) -> FloatArray:
        """Raw rows [B x dims] (or [dims]) to normalized ones."""

class Search:
    """A backend made by name over a Database."""
    def __init__(self, db: Database, backend: str = "clusters", device: Optional[int] = None,
                 **options: Any) -> None:
        """options: threads, nprobe, clusters (.mmkc path), kmeans_clusters, kmeans_iterations,
        kmeans_seed, max_batch, max_k, max_tile, warm_up."""
    def search(self, queries: FloatArray, k: int = 1,
               continuing: Union[None, int, npt.ArrayLike] = None,
               require: Sequence[str] = (), exclude: Sequence[str] = (),
               weights: Optional[Mapping[str, float]] = None,
               continuing_bias: float = 0.0, continuing_multiplier: float = 1.0,
               exclusion_window: int = 0) -> tuple[npt.NDArray[np.int64], FloatArray]:
        """queries float32 [B x dims] normalized -> (frames int64 [B x k], -1 = none; costs float32 [B x k])."""
    def _native_seconds(self, queries: FloatArray, k: int = 1, calls: int = 1) -> float:
        """Seconds per call of the same backend search made in a C++ loop (the benchmark's baseline)."""
    @property
    def name(self) -> str: ...
    @property
    def device(self) -> str: ...
    @property
    def database(self) -> Database: ...

class Crowd:
    """Motion-matched characters stepped from Python (the controller of `mmvk crowd`)."""
    def __init__(self, db: Database, agents: Optional[int] = None, backend: str = "auto",
                 rate: float = 30.0, seed: int = 1, device: Optional[int] = None,
                 scenario: Union[None, PathLike, Mapping[str, Any]] = None,
                 search_interval: float = 0.1, foot_ik: bool = True, record: bool = False,
                 title: str = "", correction_half_life: Optional[float] = None,
                 record_poses: int = 0, speed_from_animation: bool = True,
                 detail_agents: Union[None, int, str, Sequence[int], IntArray] = None,
                 wait_at_goals: float = 0.0) -> None:
        """detail_agents (with record=True): the characters the viewer page keeps in detail, their whole
        pose every tick and every search explained; None: the first 32; N: the first N; a spec such as
        '0-9,42,100-104' (`mmvk crowd --detail-agents`); or a sequence of indices."""
    def set_tags(self, agents: Union[int, Sequence[int], IntArray], require: Optional[Sequence[str]] = None,
                 exclude: Optional[Sequence[str]] = None) -> None: ...
    def step(self, desired_velocity: Optional[FloatArray] = None,
             desired_facing: Optional[FloatArray] = None) -> None:
        """One tick: own steering, or desired_velocity float32 [agents x 2|3] m/s and
        desired_facing float32 [agents] radians (None: face the velocity)."""
    def step_toward(self, next_positions: FloatArray, desired_facing: Optional[FloatArray] = None) -> None:
        """One tick toward the host's next positions, float32 [agents x 2|3] metres."""
    def run(self, seconds: float) -> None:
        """Own steering for `seconds` of simulated time."""
    def place(self, index: int, x: float, z: float, yaw: float = 0.0, frame: int = 0) -> None: ...
    @property
    def agents(self) -> int: ...
    @property
    def rate(self) -> float: ...
    @property
    def dt(self) -> float: ...
    @property
    def ticks(self) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def device(self) -> str: ...
    @property
    def walk_speed(self) -> float: ...
    @property
    def run_speed(self) -> Optional[float]: ...
    @property
    def goals(self) -> list[list[tuple[float, float]]]: ...
    @property
    def root_positions(self) -> FloatArray:
        """[agents x 3] metres, y = 0."""
    @property
    def root_yaws(self) -> FloatArray:
        """[agents] radians, 0 faces +Z."""
    @property
    def simulated_positions(self) -> FloatArray:
        """[agents x 3] the simulated (spring) root."""
    @property
    def frames(self) -> npt.NDArray[np.uint32]: ...
    @property
    def contacts(self) -> npt.NDArray[np.uint8]: ...
    @property
    def gaits(self) -> npt.NDArray[np.uint8]:
        """[agents x 2] the commanded band (0 stand, 1 walk, 2 jog, 3 run) and phase (0 stand, 1 start, 2 move, 3 stop)."""
    @property
    def resting(self) -> npt.NDArray[np.uint8]:
        """[agents] 1 while a character told to stand holds a frame with both feet down."""
    @property
    def foot_locked(self) -> npt.NDArray[np.uint8]:
        """[agents x 2] (left, right)."""
    @property
    def foot_corrections(self) -> FloatArray:
        """[agents x 2 x 3] how far each displayed foot is held from its animated pose, world metres (y = 0)."""
    @property
    def play_rates(self) -> FloatArray:
        """[agents] clip seconds per second in the last step."""
    stride_scales: FloatArray  # read-only: [agents] the root motion's scale in the last step (0: standing in place)
    root_corrections: FloatArray  # read-only: [agents x 3] the last step's root correction (the glide), metres
    @property
    def joint_positions(self) -> FloatArray:
        """[agents x joints x 3] displayed world positions, metres."""
    @property
    def skeleton(self) -> dict[str, Any]:
        """names, parents (int32), rest_offsets [joints x 3] metres, translated_joints."""
    @property
    def local_rotations(self) -> FloatArray:
        """[agents x joints x 4] displayed (after foot IK) unit quaternions (x, y, z, w), parent's frame."""
    @property
    def local_translations(self) -> FloatArray:
        """[agents x joints x 3] displayed local translations, metres."""
    @property
    def root_rotations(self) -> FloatArray:
        """[agents x 4] R_y(root_yaws) as quaternions (x, y, z, w)."""
    def write_bvh(self, folder: PathLike) -> None:
        """One BVH per recorded character (record_poses=M): folder/agent_0000.bvh, ..."""
    def write_gltf(self, path: PathLike) -> None:
        """The recorded characters (record_poses=M) in one glTF 2.0 binary (.glb)."""
    def summary(self) -> dict[str, Any]:
        """The figures of `mmvk crowd --summary`."""
    def write_html(self, path: PathLike) -> int:
        """The viewer page of the steps so far (record=True); returns bytes written."""
