#!/usr/bin/env python3
# A ROS 2 participant written with Eclipse Cyclone DDS (the `cyclonedds` Python binding,
# ROS 2's tier-1 middleware) for host/tests/dds_live.rs: publishes ROS 2-typed samples
# (std_msgs/msg/Int32 and Bool: DDS topics rt/<name>, types pkg::msg::dds_::Type_, ROS 2's
# default QoS) following a script, and reads MCAP files with the `mcap` Python reader.
#
# Usage:
#   cyclone.py publish DOMAIN STEPS_JSON   STEPS: [["wait_match", "/topic", seconds],
#       ["int32", "/topic", value], ["bool", "/topic", value], ["bad", "/topic"] (a
#       malformed std_msgs/Int32MultiArray),
#       ["sleep", seconds]]; prints "matched /topic" and "sent N" lines.
#   cyclone.py read_mcap FILE              prints one JSON line per message:
#       {"topic", "schema", "encoding", "message_encoding", "log_time", and "data"
#       decoded with mcap-ros2-support, or "error" when it does not decode}.
import json
import sys
import time
from dataclasses import dataclass


def publish(domain, steps):
    from cyclonedds.core import Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.idl import IdlStruct
    from cyclonedds.idl.types import int32, uint32
    from cyclonedds.pub import DataWriter
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration

    # rosidl's generated IDL for std_msgs/msg/Int32 and Bool, with the type names
    # rmw_cyclonedds gives them.
    @dataclass
    class Int32_(IdlStruct, typename="std_msgs::msg::dds_::Int32_"):
        data: int32

    @dataclass
    class Bool_(IdlStruct, typename="std_msgs::msg::dds_::Bool_"):
        data: bool

    # Not an Int32MultiArray: a count of 1000 dimensions and nothing after it (a
    # malformed sample).
    @dataclass
    class Short_(IdlStruct, typename="std_msgs::msg::dds_::Int32MultiArray_"):
        count: uint32

    # rmw_qos_profile_default: reliable, volatile, keep last 10.
    qos = Qos(
        Policy.Reliability.Reliable(duration(milliseconds=100)),
        Policy.Durability.Volatile,
        Policy.History.KeepLast(10),
    )
    dp = DomainParticipant(domain)
    writers = {}

    def writer(kind, topic):
        key = (kind, topic)
        if key not in writers:
            ty = {"int32": Int32_, "bool": Bool_, "bad": Short_}[kind]
            t = Topic(dp, "rt" + topic, ty, qos=qos)
            writers[key] = (DataWriter(dp, t, qos=qos), ty)
        return writers[key]

    sent = 0
    for step in steps:
        op = step[0]
        if op == "sleep":
            time.sleep(step[1])
        elif op == "wait_match":
            w, _ = writer(step[3] if len(step) > 3 else "int32", step[1])
            end = time.time() + step[2]
            while not w.get_matched_subscriptions():
                if time.time() > end:
                    print(f"no reader matched {step[1]}", file=sys.stderr)
                    sys.exit(3)
                time.sleep(0.02)
            print(f"matched {step[1]}", flush=True)
        elif op in ("int32", "bool"):
            w, ty = writer(op, step[1])
            w.write(ty(data=step[2]))
            sent += 1
        elif op == "bad":
            w, ty = writer("bad", step[1])
            w.write(ty(count=1000))
            sent += 1
        else:
            raise SystemExit(f"unknown step {step!r}")
    # Reliable delivery of the last samples before the participant goes.
    for w, _ in writers.values():
        w.wait_for_acks(duration(seconds=2))
    print(f"sent {sent}", flush=True)


def read_mcap(path):
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    factory = DecoderFactory()
    decoders = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            if channel.id not in decoders:
                decoders[channel.id] = factory.decoder_for(channel.message_encoding, schema)
            line = {
                "topic": channel.topic,
                "schema": schema.name,
                "encoding": schema.encoding,
                "message_encoding": channel.message_encoding,
                "log_time": message.log_time,
            }
            # A sample the monitor found malformed is recorded as it came: it does not
            # decode here either.
            try:
                line["data"] = decoders[channel.id](message.data).data
            except Exception as e:  # noqa: BLE001 (any decoding failure)
                line["error"] = str(e) or type(e).__name__
            print(json.dumps(line), flush=True)


if __name__ == "__main__":
    if sys.argv[1] == "publish":
        publish(int(sys.argv[2]), json.loads(sys.argv[3]))
    elif sys.argv[1] == "read_mcap":
        read_mcap(sys.argv[2])
    else:
        raise SystemExit(f"unknown command {sys.argv[1]}")
