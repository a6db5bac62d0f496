"""Reading an IMU from a ROS bag against reading the same samples from a CSV file.

Builds, in a temporary folder, a ROS 2 MCAP bag, a ROS 2 sqlite3 bag and a ROS 1 bag of N
``sensor_msgs/Imu`` messages (every 97th received out of order) and the same samples as a
CSV file, then reads each, interleaved (bag, CSV, bag, CSV, …), in a child process with
``thermocal.readers.read_recording`` (the six IMU columns), best of ``--repeat``: wall time
and peak resident memory, and the memory the IMU arrays themselves take (7 float64 columns).

    python benchmarks/bench_bags.py                 # 1e6 messages (about 4 min loaded)
    python benchmarks/bench_bags.py --quick         # 2e5 messages
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _harness import measure

READ = (
    "import warnings, sys\n"
    "from thermocal.readers import read_recording\n"
    "from thermocal.readers.options import ReadOptions\n"
    "warnings.simplefilter('ignore')\n"
    "p = sys.argv[1]\n"
    "cols = ('gyro_x','gyro_y','gyro_z','accel_x','accel_y','accel_z')\n"
    "r = ReadOptions(topic='/imu', signals=cols) if not p.endswith('.csv') else "
    "ReadOptions(time='time', time_unit='s', signals=cols, "
    "signal_unit=('rad/s',) * 3 + ('m/s^2',) * 3, temperatures=())\n"
    "rec = read_recording(p, r, keep_other=False)\n"
    "assert rec.n_samples == int(sys.argv[2]), rec.n_samples\n"
)


def _messages(kind: str, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Raw messages (n × bytes) of one layout, their header stamps and values, built from
    one serialized template with numpy (rosbags' serializer gives the template)."""
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC if kind == "ros1" else Stores.ROS2_HUMBLE)
    t = ts.types
    cov = np.zeros(9)
    v3 = t["geometry_msgs/msg/Vector3"]
    stamp = t["builtin_interfaces/msg/Time"](sec=0, nanosec=0)
    hdr = (t["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id="imu") if kind == "ros1"
           else t["std_msgs/msg/Header"](stamp=stamp, frame_id="imu"))  # fmt: skip
    msg = t["sensor_msgs/msg/Imu"](
        header=hdr, orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=cov, angular_velocity=v3(x=1.5, y=2.5, z=3.5),
        angular_velocity_covariance=cov, linear_acceleration=v3(x=4.5, y=5.5, z=6.5),
        linear_acceleration_covariance=cov,
    )  # fmt: skip
    raw = bytes(ts.serialize_ros1(msg, msg.__msgtype__) if kind == "ros1"
                else ts.serialize_cdr(msg, msg.__msgtype__))  # fmt: skip
    tmpl = np.frombuffer(raw, np.uint8)
    offs = [raw.find(np.float64(v).tobytes()) for v in (1.5, 2.5, 3.5, 4.5, 5.5, 6.5)]
    rng = np.random.default_rng(1)
    header = 1_700_000_000 * 10**9 + np.arange(n, dtype=np.int64) * 5_000_000
    values = rng.normal(0.0, 0.01, (n, 6)) + np.array([0, 0, 0, 0, 0, 9.81])
    block = np.tile(tmpl, (n, 1))
    st = 4  # sec at 4 (after the CDR header, or after ROS 1's seq)
    block[:, st : st + 4] = (header // 10**9).astype("<i4").view(np.uint8).reshape(n, 4)
    block[:, st + 4 : st + 8] = (header % 10**9).astype("<u4").view(np.uint8).reshape(n, 4)
    for j, o in enumerate(offs):
        block[:, o : o + 8] = values[:, j].astype("<f8").view(np.uint8).reshape(n, 8)
    return block, header, values


def build(base: Path, n: int) -> dict[str, Path]:
    """The three bags and the CSV of the same n samples."""
    import pandas as pd
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import StoragePlugin
    from rosbags.rosbag2 import Writer as Writer2
    from rosbags.typesys import Stores, get_typestore

    order = np.arange(n)
    for i in range(50, n - 1, 97):
        order[i], order[i + 1] = order[i + 1], order[i]
    out: dict[str, Path] = {}
    for kind in ("mcap", "sqlite3", "ros1"):
        block, header, values = _messages(kind, n)
        ts = get_typestore(Stores.ROS1_NOETIC if kind == "ros1" else Stores.ROS2_HUMBLE)
        path = base / ("imu.bag" if kind == "ros1" else kind)
        if kind == "ros1":
            w = Writer1(path)
        else:
            plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
            w = Writer2(path, version=9, storage_plugin=plugin)
        w.open()
        conn = w.add_connection("/imu", "sensor_msgs/msg/Imu", typestore=ts)
        for k, i in enumerate(order):
            w.write(conn, int(header[0]) + k * 5_000_000, block[i].tobytes())
        w.close()
        out[kind] = path
    cols = {"time": (header - header[0]) / 1e9}
    for j, c in enumerate(("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")):
        cols[c] = values[:, j]
    out["csv"] = base / "imu.csv"
    pd.DataFrame(cols).to_csv(out["csv"], index=False, float_format="%.17g")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--messages", type=int, default=1_000_000)
    ap.add_argument("--quick", action="store_true", help="2e5 messages")
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    n = 200_000 if a.quick else a.messages
    print(f"load at start: {os.getloadavg()[0]:.1f}; {n:,} messages")
    with tempfile.TemporaryDirectory() as tmp:
        files = build(Path(tmp), n)
        sizes = {k: sum(f.stat().st_size for f in (p.iterdir() if p.is_dir() else [p]))
                 for k, p in files.items()}  # fmt: skip
        best: dict[str, tuple[float, float]] = {}
        for _ in range(a.repeat):
            for kind in ("mcap", "csv", "sqlite3", "csv", "ros1", "csv"):
                s, mb = measure([sys.executable, "-c", READ, str(files[kind]), str(n)])
                old = best.get(kind, (np.inf, np.inf))
                best[kind] = (min(old[0], s), min(old[1], mb))
        base = measure([sys.executable, "-c", "import thermocal.readers, pandas, numpy"])
    arrays = n * 7 * 8 / 2**20
    print(f"the IMU arrays: {arrays:.0f} MB; interpreter with thermocal and pandas: "
          f"{base[1]:.0f} MB")  # fmt: skip
    print(f"{'file':8} {'size MB':>8} {'read s':>7} {'peak MB':>8} {'×csv time':>9} "
          f"{'over base MB':>12}")  # fmt: skip
    for kind, (s, mb) in best.items():
        print(f"{kind:8} {sizes[kind] / 2**20:8.0f} {s:7.2f} {mb:8.0f} "
              f"{s / best['csv'][0]:9.2f} {mb - base[1]:12.0f}")  # fmt: skip
    print(f"load at end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
