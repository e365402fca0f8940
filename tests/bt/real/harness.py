#!/usr/bin/env python3
# The real BehaviorTree.CPP (the `behaviortreepy` bindings) run case by case for the
# oracle's differential test (tests/tests/bt_real.rs, tests/src/bt/real.rs).
#
# Protocol: one JSON object per line on stdin, one answer per line on stdout.
#   first line out: {"version": "<BT.CPP version>", "binding": "<behaviortreepy version>"}
#   in:  {"xml": str, "scripts": {type: ["SUCCESS"|"FAILURE"|"RUNNING", ...]},
#         "ticks": int, "mode": "once"|"exactly_once", "budget": int, "read": [entry],
#         "period_ms": int (optional), "out_values": [float], "in_text": str}
#   out: {"statuses": [str], "log": [["T"|"H", uid, type], ...], "end": null |
#         {"kind": "load"|"tick"|"livelock", "tick": int, "text": str},
#         "vars": {entry: int | null}}
# `period_ms` (optional) paces the ticks: tick i begins at i * period_ms after the first,
# as an executor on a timer does (the timers of Timeout, Delay and Sleep run on wall-clock
# time); a tick that begins or ends more than a quarter period after its time ends the
# case as {"kind": "late"} (the machine was too loaded for the margins the test relies on).
# `read` (optional) names root blackboard entries to read as integers after the last
# tick (a boolean reads as 0 or 1; null: missing or not a number).
# A scripted leaf whose script holds RUNNING is a stateful action, one whose script
# does not a synchronous action (SyncActionNode: every tick calls it, as a condition's
# does; a StatefulActionNode ticked in a finished status its parent did not reset
# answers that status without a callback): on its k-th callback it answers
# script[k % len]; on_halted logs a halt (BT.CPP halts a child only while it
# is RUNNING: ControlNode::haltChild, DecoratorNode::resetChild; the differential
# confirms no other halt reaches a leaf). A finished leaf its parent did not reset is
# not called at all when ticked again (StatefulActionNode::tick). `uid` is the node's TreeNode::UID
# (BT.CPP numbers nodes from 1 in the order it creates them: depth-first pre-order with
# each SubTree node before its body); the test maps it to the oracle's node id.
# A leaf type `T<digit>...` stands for a leaf with a `string` input port `in` that answers
# SUCCESS while the text it reads is `in_text` (tests/src/bt/model.rs, `has_in_text`): the
# binding registers no ports, so its `in="{e}"` is taken out of the XML and the callback
# reads entry `e` from the node's blackboard, the entry getInput<std::string> reads (what
# the port adds, the entry created empty when the tree loads, is not reproduced: the
# generated trees create `t` first).
# Likewise a leaf type `O<digit>...` stands for a leaf with a `float64` output port `out`
# writing out_values[k % len] on its k-th callback (`has_out`; both values come with the
# request, from `model::OUT_VALUES` and `model::IN_TEXT`): its `out="{e}"` is taken out
# and the callback stores the double in entry `e` of its blackboard, as setOutput<double>
# does (the port's empty entry at load is not reproduced: reading it before the first
# write throws either way, "not initialized" or "not found").
# A root tick that makes more than `budget` leaf callbacks is a livelock: the leaves
# then answer RUNNING (a synchronous one FAILURE) without logging (so the tick can end), and the case stops there
# with the log cut at the start of that tick.
import ctypes
import json
import os
import re
import sys
import time

import behaviortreepy as bt
import behaviortreepy._behaviortreepy as native

STATUS = {
    "SUCCESS": bt.NodeStatus.SUCCESS,
    "FAILURE": bt.NodeStatus.FAILURE,
    "RUNNING": bt.NodeStatus.RUNNING,
}


def library_version():
    # BT::LibraryVersionString() is exported by the compiled module but not bound.
    try:
        f = ctypes.CDLL(native.__file__)._ZN2BT20LibraryVersionStringEv
        f.restype = ctypes.c_char_p
        return f().decode()
    except (OSError, AttributeError):
        return "unknown"


class Case:
    def __init__(self, scripts, budget):
        self.scripts = scripts
        self.budget = budget
        self.calls = 0
        self.over = False
        self.live = True
        self.k = {}
        self.log = []
        # Leaf type -> the entry its `in` port named (`T<digit>...` leaves), its `out`
        # port (`O<digit>...` leaves).
        self.inputs = {}
        self.outputs = {}
        self.out_values = []
        self.in_text = None


# A `T<digit>...` leaf's input port, and an `O<digit>...` leaf's output port.
IN_PORT = re.compile(r'(<(T[0-9]+)\b[^>]*?) in="\{([A-Za-z_][A-Za-z_0-9]*)\}"')
OUT_PORT = re.compile(r'(<(O[0-9]+)\b[^>]*?) out="\{([A-Za-z_][A-Za-z_0-9]*)\}"')

cur = None
# One factory per set of leaf kinds: a type name is registered once per factory, and the
# same name is stateful in one case and synchronous in another.
factories = {}


def factory_for(scripts):
    kinds = tuple(sorted((n, "RUNNING" in s) for n, s in scripts.items()))
    f = factories.get(kinds)
    if f is None:
        if len(factories) > 256:
            factories.clear()
        f = bt.BehaviorTreeFactory()
        for name, stateful in kinds:
            # A built-in's name is refused ("already registered"): the case ends as a
            # load error, and the factory is not kept.
            register(f, name, stateful)
        factories[kinds] = f
    return f


def register(factory, name, stateful):
    # What a leaf answers once the case is over: RUNNING ends a tick soonest, but a
    # synchronous action may not answer it ("SyncActionNode MUST never return RUNNING").
    idle = bt.NodeStatus.RUNNING if stateful else bt.NodeStatus.FAILURE

    def answer(node):
        c = cur
        if c is None or not c.live:
            return idle
        c.calls += 1
        if c.calls > c.budget:
            c.over = True
            return idle
        uid = node.uid()
        k = c.k.get(uid, 0)
        c.k[uid] = k + 1
        c.log.append(["T", uid, name])
        s = c.scripts[name]
        out = c.outputs.get(name)
        if out is not None:
            node.config().blackboard.set_double(out, c.out_values[k % len(c.out_values)])
        entry = c.inputs.get(name)
        if entry is not None:
            try:
                text = node.config().blackboard.get_string(entry)
            except Exception:  # no such entry, or not a string
                text = None
            if text == c.in_text:
                return bt.NodeStatus.SUCCESS
        return STATUS[s[k % len(s)]]

    def halted(node):
        c = cur
        if c is not None and c.live and not c.over:
            c.log.append(["H", node.uid(), name])

    if stateful:
        factory.register_simple_stateful_action(name, answer, answer, halted)
    else:
        factory.register_simple_action(name, answer)


def run(req):
    global cur
    c = Case(req["scripts"], req.get("budget", 1000))
    cur = c
    statuses = []
    end = None
    tree = None
    try:
        factory = factory_for(req["scripts"])
        xml = req["xml"]
        c.out_values = req.get("out_values", [])
        c.in_text = req.get("in_text")
        for m in IN_PORT.finditer(xml):
            c.inputs[m.group(2)] = m.group(3)
        for m in OUT_PORT.finditer(xml):
            c.outputs[m.group(2)] = m.group(3)
        xml = OUT_PORT.sub(r"\1", IN_PORT.sub(r"\1", xml))
        tree = factory.create_tree_from_text(xml)
    except Exception as e:  # BT.CPP refuses the tree
        end = {"kind": "load", "tick": 0, "text": str(e)}
    if tree is not None:
        tick = tree.tick_once if req["mode"] == "once" else tree.tick_exactly_once
        period = req.get("period_ms")
        t0 = time.monotonic()
        for i in range(req["ticks"]):
            mark = len(c.log)
            c.calls = 0
            if period:
                due = t0 + i * period / 1000.0
                wait = due - time.monotonic()
                if wait > 0:
                    time.sleep(wait)
            try:
                s = tick()
            except Exception as e:
                end = {"kind": "tick", "tick": i, "text": str(e)}
                break
            if period:
                late = (time.monotonic() - due) * 1000.0
                if late > period / 4.0:
                    end = {"kind": "late", "tick": i, "text": "tick %d ended %.1f ms after its time" % (i, late)}
                    break
            if c.over:
                del c.log[mark:]
                end = {"kind": "livelock", "tick": i, "text": "over budget"}
                break
            statuses.append(s.name)
    vars = {}
    if tree is not None:
        bb = tree.root_blackboard()
        for k in req.get("read", []):
            try:
                vars[k] = bb.get_int(k)
            except Exception:
                vars[k] = None
    # Halting what still runs is not part of the case. Halt it here, where a throwing
    # `_onHalted` script is a Python exception: the destructor halts again, and a throw
    # there aborts the process.
    # `Tree::haltTree` halts every node, running or not, so every `_onHalted` script
    # runs: the entries `read` names are made to exist first (the generator's statements
    # cannot throw otherwise), as a throw from the destructor ends the process.
    c.live = False
    if tree is not None:
        for k in req.get("read", []):
            if vars.get(k) is None:
                try:
                    bb.set_int(k, 0)
                except Exception:
                    pass
        try:
            tree.halt_tree()
        except Exception:
            pass
    del tree
    cur = None
    return {"statuses": statuses, "log": c.log, "end": end, "vars": vars}


def main():
    # BT.CPP prints warnings on its C++ stdout: keep our answers on a stream of their own.
    out = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    binding = getattr(bt, "__version__", "unknown")
    out.write(json.dumps({"version": library_version(), "binding": binding}) + "\n")
    out.flush()
    for line in sys.stdin:
        if not line.strip():
            continue
        out.write(json.dumps(run(json.loads(line))) + "\n")
        out.flush()


if __name__ == "__main__":
    main()
