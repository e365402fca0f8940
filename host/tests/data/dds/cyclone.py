#!/usr/bin/env python3
# A ROS 2 participant written with Eclipse Cyclone DDS (the `cyclonedds` Python binding,
# ROS 2's tier-1 middleware) for host/tests/dds_live.rs: publishes ROS 2-typed samples
# (std_msgs/msg/Int32 and Bool: DDS topics rt/<name>, types pkg::msg::dds_::Type_, ROS 2's
# default QoS) following a script, and reads MCAP files with the `mcap` Python reader.
#
# Usage:
#   cyclone.py publish DOMAIN STEPS_JSON   STEPS: [["wait_match", "/topic", seconds],
#       ["int32", "/topic", value], ["bool", "/topic", value], ["bad", "/topic"] (a
#       malformed std_msgs/Int32MultiArray), ["int32", "/topic", value, {"age": s}] (written
#       with a source timestamp s seconds in the past),
#       ["qos", "/topic", {"reliability": "best_effort", "durability": "transient_local",
#       "depth": N}] (the QoS of the topic's writer, created after it; ROS 2's names),
#       ["say", "text"] (prints the text), ["sleep", seconds]]; prints "matched /topic" and
#       "sent N" lines.
#   cyclone.py subscribe DOMAIN SPEC_JSON  SPEC: {"topics": [["/topic", "TYPE"] or
#       ["/topic", "TYPE", QOS] (QOS as for publish's "qos" step), ...],
#       "count": N, "seconds": S}: reads the topics (TYPE: a key of ros_types()) with ROS
#       2's default QoS, prints "ready" once its readers exist, then one JSON line per
#       sample {"topic", "data": the sample's fields} until N samples or S seconds, or
#       until SIGINT; it then leaves at once (os._exit), without tearing the participant
#       down: once, a SIGINT raised as KeyboardInterrupt left it hanging past 30 s.
#   cyclone.py call DOMAIN SPEC_JSON       SPEC: {"service": "/s", "calls": [[a, b], ...],
#       "seconds": S}: a ROS 2 client of example_interfaces/srv/AddTwoInts as
#       rmw_cyclonedds makes one: requests on rq/<s>Request, replies on rr/<s>Reply, each
#       sample headed by the request id (uint64 client guid, int64 sequence number);
#       prints "matched", then one JSON line per reply {"seq", "sum"} of its own guid.
#   cyclone.py read_mcap FILE              prints one JSON line per message:
#       {"topic", "schema", "encoding", "message_encoding", "log_time", and "data"
#       decoded with mcap-ros2-support, or "error" when it does not decode}.
import json
import os
import signal
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
    topic_qos = {}

    def writer(kind, topic):
        key = (kind, topic)
        if key not in writers:
            ty = {"int32": Int32_, "bool": Bool_, "bad": Short_}[kind]
            q = topic_qos.get(topic, qos)
            t = Topic(dp, "rt" + topic, ty, qos=q)
            writers[key] = (DataWriter(dp, t, qos=q), ty)
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
        elif op == "qos":
            topic_qos[step[1]] = ros_qos(step[2])
        elif op == "say":
            print(step[1], flush=True)
        elif op in ("int32", "bool"):
            w, ty = writer(op, step[1])
            opts = step[3] if len(step) > 3 else {}
            if "age" in opts:
                # The sample's source timestamp, `age` seconds before now (ns since the
                # UNIX epoch, the time DDS writes in the sample's INFO_TS).
                w.write(ty(data=step[2]), timestamp=time.time_ns() - int(opts["age"] * 1e9))
            else:
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


def ros_qos(settings):
    """A Cyclone DDS QoS from ROS 2's names for the policies (rmw_qos_profile_t's
    reliability, durability, history and depth), over ROS 2's default profile."""
    from cyclonedds.core import Policy, Qos
    from cyclonedds.util import duration

    depth = settings.get("depth", 10)
    reliability = {
        "reliable": Policy.Reliability.Reliable(duration(milliseconds=100)),
        "best_effort": Policy.Reliability.BestEffort,
    }[settings.get("reliability", "reliable")]
    durability = {
        "volatile": Policy.Durability.Volatile,
        "transient_local": Policy.Durability.TransientLocal,
    }[settings.get("durability", "volatile")]
    history = {
        "keep_last": Policy.History.KeepLast(depth),
        "keep_all": Policy.History.KeepAll,
    }[settings.get("history", "keep_last")]
    return Qos(reliability, durability, history)


def ros_types():
    """rosidl's generated IDL of the types the tests read, with rmw_cyclonedds's type names
    (`pkg::msg::dds_::Type_`, a service's event `pkg::srv::dds_::Name_Event_`)."""
    from cyclonedds.idl import IdlStruct
    from cyclonedds.idl.types import array, float32, int8, int32, int64, sequence, uint8, uint32

    @dataclass
    class Int32_(IdlStruct, typename="std_msgs::msg::dds_::Int32_"):
        data: int32

    @dataclass
    class Bool_(IdlStruct, typename="std_msgs::msg::dds_::Bool_"):
        data: bool

    @dataclass
    class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
        sec: int32
        nanosec: uint32

    @dataclass
    class Header_(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
        stamp: Time_
        frame_id: str

    @dataclass
    class BatteryState_(IdlStruct, typename="sensor_msgs::msg::dds_::BatteryState_"):
        header: Header_
        voltage: float32
        temperature: float32
        current: float32
        charge: float32
        capacity: float32
        design_capacity: float32
        percentage: float32
        power_supply_status: uint8
        power_supply_health: uint8
        power_supply_technology: uint8
        present: bool
        cell_voltage: sequence[float32]
        cell_temperature: sequence[float32]
        location: str
        serial_number: str

    @dataclass
    class ServiceEventInfo_(IdlStruct, typename="service_msgs::msg::dds_::ServiceEventInfo_"):
        event_type: uint8
        stamp: Time_
        client_gid: array[uint8, 16]
        sequence_number: int64

    @dataclass
    class SetPoi_Request_(IdlStruct, typename="scheduler_interfaces_dummy::srv::dds_::SetPoi_Request_"):
        poi_number: int32

    @dataclass
    class SetPoi_Response_(IdlStruct, typename="scheduler_interfaces_dummy::srv::dds_::SetPoi_Response_"):
        is_ok: bool

    @dataclass
    class SetPoi_Event_(IdlStruct, typename="scheduler_interfaces_dummy::srv::dds_::SetPoi_Event_"):
        info: ServiceEventInfo_
        request: sequence[SetPoi_Request_, 1]
        response: sequence[SetPoi_Response_, 1]

    @dataclass
    class NavigationStatus_(IdlStruct, typename="navigation_interfaces_dummy::msg::dds_::NavigationStatus_"):
        status: int8

    return {
        "int32": Int32_,
        "bool": Bool_,
        "battery_state": BatteryState_,
        "set_poi_event": SetPoi_Event_,
        "navigation_status": NavigationStatus_,
    }


def subscribe(domain, spec):
    import dataclasses

    from cyclonedds.core import Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration

    types = ros_types()
    qos = Qos(
        Policy.Reliability.Reliable(duration(milliseconds=100)),
        Policy.Durability.Volatile,
        Policy.History.KeepLast(10),
    )
    dp = DomainParticipant(domain)
    readers = []
    for entry in spec["topics"]:
        topic, kind = entry[0], entry[1]
        q = ros_qos(entry[2]) if len(entry) > 2 else qos
        t = Topic(dp, "rt" + topic, types[kind], qos=q)
        readers.append((topic, DataReader(dp, t, qos=q)))
    # SIGINT ends the loop between takes instead of raising inside the binding.
    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(True))
    print("ready", flush=True)
    end = time.time() + spec["seconds"]
    got = 0
    while not stop and got < spec["count"] and time.time() < end:
        idle = True
        for topic, r in readers:
            for sample in r.take(N=64):
                idle = False
                # Not data: the writer's unregistration when its participant leaves.
                if not sample.sample_info.valid_data:
                    continue
                got += 1
                line = {"topic": topic, "data": dataclasses.asdict(sample)}
                # A uint8 array (client_gid) comes as bytes: as a list of numbers.
                print(json.dumps(line, default=list), flush=True)
        if idle:
            time.sleep(0.005)
    # Every line was flushed as it was printed; nothing is left to write.
    os._exit(0)


def call(domain, spec):
    from cyclonedds.core import Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.idl import IdlStruct
    from cyclonedds.idl.types import int64, uint64
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration

    # rmw_cyclonedds's service samples: the request id header (cdds_request_header_t:
    # guid, seq) written before the request's or the response's own fields.
    @dataclass
    class Request_(IdlStruct, typename="example_interfaces::srv::dds_::AddTwoInts_Request_"):
        guid: uint64
        seq: int64
        a: int64
        b: int64

    @dataclass
    class Response_(IdlStruct, typename="example_interfaces::srv::dds_::AddTwoInts_Response_"):
        guid: uint64
        seq: int64
        sum: int64

    # rmw_qos_profile_services_default: reliable, volatile, keep last 10.
    qos = Qos(
        Policy.Reliability.Reliable(duration(milliseconds=100)),
        Policy.Durability.Volatile,
        Policy.History.KeepLast(10),
    )
    dp = DomainParticipant(domain)
    name = spec["service"].lstrip("/")
    w = DataWriter(dp, Topic(dp, f"rq/{name}Request", Request_, qos=qos), qos=qos)
    r = DataReader(dp, Topic(dp, f"rr/{name}Reply", Response_, qos=qos), qos=qos)
    end = time.time() + spec["seconds"]
    while not (w.get_matched_subscriptions() and r.get_matched_publications()):
        if time.time() > end:
            print("the server was never matched", file=sys.stderr)
            sys.exit(3)
        time.sleep(0.02)
    # The server's side of discovery: its reply writer must know our reader too.
    time.sleep(3.0)
    print("matched", flush=True)
    guid = 0x0102030405060708
    for seq, (a, b) in enumerate(spec["calls"], start=1):
        w.write(Request_(guid=guid, seq=seq, a=a, b=b))
        got = None
        while got is None and time.time() < end:
            for sample in r.take(N=16):
                if not sample.sample_info.valid_data or sample.guid != guid:
                    continue
                got = sample
            time.sleep(0.005)
        if got is None:
            print(f"no reply to request {seq}", file=sys.stderr)
            sys.exit(4)
        print(json.dumps({"seq": got.seq, "sum": got.sum}), flush=True)


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
    elif sys.argv[1] == "subscribe":
        subscribe(int(sys.argv[2]), json.loads(sys.argv[3]))
    elif sys.argv[1] == "call":
        call(int(sys.argv[2]), json.loads(sys.argv[3]))
    elif sys.argv[1] == "read_mcap":
        read_mcap(sys.argv[2])
    else:
        raise SystemExit(f"unknown command {sys.argv[1]}")
