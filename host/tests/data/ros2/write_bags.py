#!/usr/bin/env python3
"""Writes the same ROS 2 messages as rosbag2 recordings with software other teams wrote
(`rosbags`: an MCAP bag and a SQLite .db3 bag; `mcap-ros2-support`: an MCAP file) and as
our CSV trace, for host/tests/replay_bags.rs.

Usage: write_bags.py OUT_DIR
Writes OUT_DIR/rosbags_mcap/ (rosbag2 folder), OUT_DIR/rosbags_db3/ (rosbag2 folder),
OUT_DIR/mcap_ros2.mcap and OUT_DIR/points.csv (columns: the ports of
host/tests/data/ros2/properties.xml, time in ns since the first message).
"""
import ast
import re
import sys
from pathlib import Path

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore, get_types_from_msg
from mcap_ros2.writer import Writer as McapWriter

OUT = Path(sys.argv[1])
T0 = 1_700_000_000_000_000_000  # log time of the first message, ns

# The service's types, as `ros2 bag record --all-services` records them.
SRV = "example_interfaces/srv/AddTwoInts"
EVENT_DEF = (
    "service_msgs/ServiceEventInfo info\n"
    "AddTwoInts_Request[<=1] request\n"
    "AddTwoInts_Response[<=1] response\n"
    "================================================================================\n"
    "MSG: service_msgs/ServiceEventInfo\n"
    "uint8 REQUEST_SENT = 0\nuint8 REQUEST_RECEIVED = 1\nuint8 RESPONSE_SENT = 2\n"
    "uint8 RESPONSE_RECEIVED = 3\nuint8 event_type\nbuiltin_interfaces/Time stamp\n"
    "char[16] client_gid\nint64 sequence_number\n"
    "================================================================================\n"
    "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
    "================================================================================\n"
    "MSG: example_interfaces/AddTwoInts_Request\nint64 a\nint64 b\n"
    "================================================================================\n"
    "MSG: example_interfaces/AddTwoInts_Response\nint64 sum\n"
)


def typestore():
    ts = get_typestore(Stores.ROS2_JAZZY)
    t = {}
    t.update(get_types_from_msg("int64 a\nint64 b\n", SRV + "_Request"))
    t.update(get_types_from_msg("int64 sum\n", SRV + "_Response"))
    t.update(get_types_from_msg(
        "service_msgs/msg/ServiceEventInfo info\n"
        f"{SRV}_Request[<=1] request\n{SRV}_Response[<=1] response\n", SRV + "_Event"))
    # rosbags names a type read from .msg text `pkg/srv/msg/T`; a service's parts are `pkg/srv/T`.
    text = re.sub(r"<Nodetype\.\w+: (\d+)>", r"\1", repr(t).replace("srv/msg/", "srv/"))
    ts.register(ast.literal_eval(text))
    return ts


TS = typestore()
Int32 = TS.types["std_msgs/msg/Int32"]
Bool = TS.types["std_msgs/msg/Bool"]
Battery = TS.types["sensor_msgs/msg/BatteryState"]
Header = TS.types["std_msgs/msg/Header"]
Time = TS.types["builtin_interfaces/msg/Time"]
Event = TS.types[SRV + "_Event"]
Info = TS.types["service_msgs/msg/ServiceEventInfo"]
Req = TS.types[SRV + "_Request"]
Resp = TS.types[SRV + "_Response"]


def battery(t, pct, cells, frame):
    return Battery(
        header=Header(stamp=Time(sec=t // 1_000_000_000, nanosec=t % 1_000_000_000), frame_id=frame),
        voltage=12.0, temperature=20.0, current=-1.0, charge=1.0, capacity=2.0,
        design_capacity=2.0, percentage=pct, power_supply_status=2, power_supply_health=1,
        power_supply_technology=2, present=True,
        cell_voltage=np.array(cells, dtype=np.float32),
        cell_temperature=np.array([], dtype=np.float32), location="slot", serial_number="x1")


def event(t, kind, a, b, seq):
    req = [Req(a=a, b=b)] if kind in (0, 1) else []
    resp = [Resp(sum=a + b)] if kind in (2, 3) else []
    info = Info(event_type=kind, stamp=Time(sec=t // 1_000_000_000, nanosec=t % 1_000_000_000),
                client_gid=np.array([7] * 16, dtype=np.uint8), sequence_number=seq)
    return Event(info=info, request=req, response=resp)


# (time since T0 in ns, topic, type, message, {port: CSV cell})
POINTS = []


def add(dt, topic, ty, msg, cells):
    POINTS.append((dt, topic, ty, msg, cells))


MS = 1_000_000
t = 0
level = 100
for i in range(40):
    t = i * 300 * MS  # the level every 0.3 s, except for a gap of 1.5 s after message 20
    if i > 20:
        t += 1500 * MS
    level -= 3
    add(t, "/battery_level", "std_msgs/msg/Int32", Int32(data=level), {"level": str(level), "level_pub": "true"})
    if i % 4 == 1:
        followed = i % 8 == 1
        add(t + 10 * MS, "/is_followed", "std_msgs/msg/Bool", Bool(data=followed),
            {"followed": "true" if followed else "false"})
    if i == 20:
        # A silent stretch of /battery_level, seen at a message of another topic.
        add(t + 1200 * MS, "/is_followed", "std_msgs/msg/Bool", Bool(data=False), {"followed": "false"})
    if i % 5 == 2:
        cells = [4.0 - i * 0.03125, 3.75] if i != 27 else [3.5, 3.5, 3.0]
        pct = float(np.float32(level / 100.0 if i != 37 else 0.125))
        frame = "base" if i < 30 else "dock"
        ts_ = T0 + t + 20 * MS
        add(t + 20 * MS, "/battery", "sensor_msgs/msg/BatteryState", battery(ts_, pct, cells, frame),
            {"pct": repr(pct), "cell0": repr(float(np.float32(cells[0]))),
             "stamp_sec": str(ts_ // 1_000_000_000), "frame": frame})
    if i % 6 == 3:
        a, b = i - 20, (6 if i == 33 else 5)
        seq = i
        base = t + 30 * MS
        add(base, "/add/_service_event", SRV + "_Event", event(T0 + base, 0, a, b, seq), {})
        add(base + 1 * MS, "/add/_service_event", SRV + "_Event", event(T0 + base + MS, 1, a, b, seq),
            {"a": str(a), "add_req": "true"})
        late = 700 if i == 27 else 100
        add(base + late * MS, "/add/_service_event", SRV + "_Event",
            event(T0 + base + late * MS, 2, a, b, seq), {"sum": str(a + b), "add_resp": "true"})
        add(base + (late + 1) * MS, "/add/_service_event", SRV + "_Event",
            event(T0 + base + (late + 1) * MS, 3, a, b, seq), {})
POINTS.sort(key=lambda p: p[0])

COLUMNS = ["level", "level_pub", "followed", "pct", "cell0", "stamp_sec", "frame", "a", "add_req", "sum", "add_resp"]
with open(OUT / "points.csv", "w") as f:
    f.write("time," + ",".join(COLUMNS) + "\n")
    for dt, _, _, _, cells in POINTS:
        f.write(str(dt) + "," + ",".join(cells.get(c, "") for c in COLUMNS) + "\n")

TOPICS = {}
for _, topic, ty, _, _ in POINTS:
    TOPICS.setdefault(topic, ty)


def msgdef(ty):
    if ty == SRV + "_Event":
        return EVENT_DEF
    return TS.generate_msgdef(ty, ros_version=2)[0]


def write_rosbags(path, plugin, embed_service_def):
    w = Writer(path, version=9, storage_plugin=plugin)
    w.open()
    conns = {}
    for topic, ty in TOPICS.items():
        if ty == SRV + "_Event":
            # rosbags cannot generate a definition for a service's types: give ours (MCAP),
            # or none at all (.db3: replay finds the type among the interface packages).
            kw = {"msgdef": EVENT_DEF if embed_service_def else "",
                  "rihs01": "RIHS01_" + "0" * 64}
            conns[topic] = w.add_connection(topic, ty, typestore=TS, **kw)
        else:
            conns[topic] = w.add_connection(topic, ty, typestore=TS)
    for dt, topic, ty, msg, _ in POINTS:
        w.write(conns[topic], T0 + dt, TS.serialize_cdr(msg, ty))
    w.close()


write_rosbags(OUT / "rosbags_mcap", StoragePlugin.MCAP, True)
write_rosbags(OUT / "rosbags_db3", StoragePlugin.SQLITE3, False)


def as_dict(msg):
    """A rosbags message as the plain dicts and lists mcap-ros2-support encodes."""
    if hasattr(msg, "__dataclass_fields__"):
        return {k: as_dict(getattr(msg, k)) for k in msg.__dataclass_fields__ if k != "__msgtype__"}
    if isinstance(msg, np.ndarray):
        return [as_dict(x) for x in msg.tolist()]
    if isinstance(msg, list):
        return [as_dict(x) for x in msg]
    return msg


with open(OUT / "mcap_ros2.mcap", "wb") as f:
    w = McapWriter(f)
    # mcap-ros2-support 0.6.0 encodes std_msgs itself but cannot encode a
    # builtin_interfaces/Time ("Writing for type time is not implemented"): messages with
    # a stamp go through its MCAP writer (the `mcap` package's) as rosbags encoded them.
    raw = w._writer
    schemas, channels = {}, {}
    for topic, ty in TOPICS.items():
        if ty.startswith("std_msgs/"):
            schemas[ty] = w.register_msgdef(ty, msgdef(ty))
        else:
            sid = raw.register_schema(name=ty, encoding="ros2msg", data=msgdef(ty).encode())
            channels[topic] = raw.register_channel(topic=topic, message_encoding="cdr", schema_id=sid)
    for seq, (dt, topic, ty, msg, _) in enumerate(POINTS):
        if ty in schemas:
            w.write_message(topic=topic, schema=schemas[ty], message=as_dict(msg),
                            log_time=T0 + dt, publish_time=T0 + dt)
        else:
            raw.add_message(channel_id=channels[topic], log_time=T0 + dt, publish_time=T0 + dt,
                            data=bytes(TS.serialize_cdr(msg, ty)), sequence=seq)
    w.finish()
print(f"{len(POINTS)} messages on {len(TOPICS)} topics")
