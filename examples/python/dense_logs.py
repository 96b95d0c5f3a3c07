"""Monitor real robot logs in dense time: a ROS 2 bag and a CAN log, each one call away.

The example writes both logs itself (nothing is downloaded), reads each back into a pandas
DataFrame with one row per time stamp and NaN where a signal has no new sample, and
monitors it with a dense-time spec: "within 0.25 s of coming nearer than 0.5 m to an
obstacle, slow below 0.2 m/s and stay slow for 1.5 s".

- The ROS 2 bag (written and read with `rosbags`): `/dist` every 100 ms and `/speed` at
  irregular times, stamped in nanoseconds since the epoch as ROS 2 stamps them. The spec's
  bounds are in nanoseconds, and the stamps stay whole numbers all the way: no rounding.
- The CAN log (an ASC file written and read with `python-can`): frame 0x120 carries the
  distance (uint16, millimetres), frame 0x2A0 the wheel speed (uint16, 0.01 m/s), decoded
  by a two-line signal layout below. Stamps are in seconds; the spec is
  `examples/dense/braking.hstl`.

Run it with the package and the two readers installed:

    pip install ./python rosbags python-can pandas
    python examples/python/dense_logs.py
"""

from __future__ import annotations

import struct
import sys
import tempfile
from pathlib import Path

from typing import Any, Callable

import pandas as pd

import hstl

HERE = Path(__file__).resolve().parent
BRAKING = HERE.parent / "dense" / "braking.hstl"

# The braking rule with its bounds in nanoseconds (0.25 s and 1.5 s), for ROS 2 stamps.
BRAKING_NS = """
spec BrakingNs {
    state { t: time, dist: float, speed: float }
    let Near = dist < 0.5;
    let Brakes = Near -> eventually[0..=250000000] always[0..=1500000000] speed < 0.2;
    task always Brakes;
}
"""

EPOCH_NS = 1_700_000_000_000_000_000  # 2023-11-14, as a ROS 2 clock would stamp


def approach(brake_delay_s: float) -> list[tuple[float, str, float]]:
    """A robot that drives at 0.8 m/s towards an obstacle, comes near it at 0.6 s, and
    brakes `brake_delay_s` later: `(seconds, topic, value)` samples, each signal at its
    own rate."""
    samples: list[tuple[float, str, float]] = []
    for k in range(26):  # the range sensor, every 100 ms
        t = k * 0.1
        samples.append((t, "dist", round(max(0.3, 1.7 - 1.8 * t) if t < 1.6 else 0.3 + (t - 1.6), 3)))
    brake = 0.6 + brake_delay_s
    for t in (0.0, 0.13, 0.31, 0.52, brake - 0.07, brake, brake + 0.4, 1.3, 1.9, 2.45):
        samples.append((round(t, 3), "speed", 0.8 if t < brake else 0.1))
    samples.sort()
    return samples


def write_ros2_bag(path: Path, samples: list[tuple[float, str, float]]) -> None:
    """A ROS 2 bag (sqlite3, format 9) with `std_msgs/msg/Float64` on `/dist` and `/speed`."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    Float64 = store.types["std_msgs/msg/Float64"]
    with Writer(path, version=9) as writer:
        topics = {name: writer.add_connection(f"/{name}", Float64.__msgtype__, typestore=store) for name in ("dist", "speed")}
        for t, name, value in samples:
            stamp = EPOCH_NS + round(t * 1e9)
            writer.write(topics[name], stamp, store.serialize_cdr(Float64(data=value), Float64.__msgtype__))


def read_ros2_bag(path: Path) -> pd.DataFrame:
    """One row per stamp (int64 nanoseconds), one column per topic, NaN where a topic has
    no message at that stamp."""
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    rows = []
    with Reader(path) as reader:
        for connection, stamp, raw in reader.messages():
            msg = store.deserialize_cdr(raw, connection.msgtype)
            rows.append({"t": stamp, connection.topic.lstrip("/"): msg.data})
    return merge(rows)


# The CAN signal layout: frame id -> (signal, decode of the frame's data).
CAN_LAYOUT: dict[int, tuple[str, Callable[[bytes], float]]] = {
    0x120: ("dist", lambda data: struct.unpack_from(">H", data)[0] / 1000.0),  # millimetres
    0x2A0: ("speed", lambda data: struct.unpack_from(">H", data)[0] / 100.0),  # 0.01 m/s
}


def write_can_log(path: Path, samples: list[tuple[float, str, float]]) -> None:
    """An ASC log of the two frames (plus an unrelated one the layout ignores)."""
    import can

    encode = {"dist": (0x120, 1000.0), "speed": (0x2A0, 100.0)}
    with can.ASCWriter(str(path)) as writer:
        for t, name, value in samples:
            frame, scale = encode[name]
            data = struct.pack(">H", round(value * scale)) + bytes(6)
            writer.on_message_received(can.Message(timestamp=t, arbitration_id=frame, data=data, is_extended_id=False))
            if name == "dist":
                writer.on_message_received(can.Message(timestamp=t, arbitration_id=0x7DF, data=bytes(8), is_extended_id=False))


def read_can_log(path: Path) -> pd.DataFrame:
    """The frames the layout knows, decoded: one row per stamp (seconds), NaN where a
    signal has no frame at that stamp."""
    import can

    rows = []
    for msg in can.ASCReader(str(path)):
        if msg.arbitration_id in CAN_LAYOUT:
            name, decode = CAN_LAYOUT[msg.arbitration_id]
            rows.append({"t": round(msg.timestamp, 6), name: decode(msg.data)})
    return merge(rows)


def merge(rows: list[Any]) -> pd.DataFrame:
    """Samples as one row per distinct stamp: the values given at that stamp, NaN for the
    rest (a DataFrame's `groupby(...).first()` skips NaN)."""
    df = pd.DataFrame(rows, columns=["t", "dist", "speed"])
    return df.groupby("t", as_index=False, sort=True).first()


def report(name: str, spec: hstl.Spec, df: pd.DataFrame, unit: str) -> float:
    """Monitors `df` and prints what the result shows."""
    value = spec.robustness(df)
    times, values = spec.signal(df, formula="Brakes")
    print(f"{name}: {len(df)} rows, time column {df['t'].dtype}, first stamp {df['t'].iloc[0]}")
    print(f"  robustness of `{spec.name}` at the first stamp: {value}")
    print("  `Brakes` over time (change points):")
    for t, v in zip(times.tolist(), values.tolist()):
        print(f"    {t} {unit}: {v:+.2f}")
    if value >= 0:
        print("  -> the robot always slowed within 0.25 s of coming near and stayed slow for 1.5 s")
    else:
        first = next(t for t, v in zip(times.tolist(), values.tolist()) if v < 0)
        print(f"  -> violated: from {first} {unit} the robot came near and did not slow down in time")
    return value


def main(out: Path) -> tuple[float, float]:
    bag = out / "approach_bag"
    write_ros2_bag(bag, approach(brake_delay_s=0.15))
    ros = report("ROS 2 bag", hstl.Spec.parse(BRAKING_NS), read_ros2_bag(bag), "ns")

    asc = out / "approach.asc"
    write_can_log(asc, approach(brake_delay_s=0.4))
    can_value = report("CAN log", hstl.Spec.load(BRAKING), read_can_log(asc), "s")
    return ros, can_value


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        ros, can_value = main(Path(tmp))
    sys.exit(0 if ros >= 0 > can_value else 1)
