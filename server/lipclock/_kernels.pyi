# Stub for the C extension built from csrc/ (see csrc/module.c for the checks it makes).
import numpy as np

Buffer = np.ndarray

KLATT_STATE_SIZE: int

def klatt_render(frames: Buffer, n_par: int, sample_rate: int, start: int, end: int,
                 state: Buffer, voice: Buffer, out: Buffer, /) -> None: ...
def spring_integrate(vis_idx: Buffer, targets: Buffer, closure: Buffer, rest: Buffer,
                     mass: Buffer, k: Buffer, c: Buffer, k_cl: float, c_cl: float,
                     lips: Buffer, edges: Buffer, k_nb: float, lip_pairs: Buffer, dt: float,
                     frame_pos: Buffer, out: Buffer, /) -> None: ...
def bigram_stitch(fs: Buffer, bounds: Buffer, ids: Buffer, pose_id: Buffer, ku: Buffer,
                  kw: Buffer, nk: Buffer, n_pose: int, w: Buffer, /) -> None: ...
def bigram_speed_limit(w: Buffer, step: float, /) -> None: ...
def limit_node_speed(nodes: Buffer, n_nodes: int, max_step: float, /) -> None: ...
