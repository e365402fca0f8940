// hindsight report and the live page of `monitor --serve`: draws a run as a timeline
// (plain JavaScript and SVG, inline). The report draws each saved failing run once; the
// live page's own script (`live/page_live.js`) feeds one timeline point by point.
// Lanes: the messages (sends above, receives below), one per property variable (numbers
// as steps, booleans and text as bands), one per verdict (true green, false red, the first
// false point marked and linked to its formula). Wheel or buttons zoom, dragging pans,
// hover shows a point's state, a click pins it, arrow keys step point by point.
// Many points per pixel are merged, so a long run draws as fast as its width allows.
// The page counts its own script errors in <body data-errors> and how many timelines
// it drew in <body data-rendered> (read by the browser test).
"use strict";
(function () {
  var body = document.body;
  var errors = 0;
  function countError() {
    errors += 1;
    body.setAttribute("data-errors", String(errors));
    var shown = document.getElementById("errors");
    if (shown) shown.textContent = String(errors);
  }
  window.addEventListener("error", countError);
  window.addEventListener("unhandledrejection", countError);

  var LABEL = 180, LANE = 22, AXIS = 24, PAD = 4, RIGHT = 12;
  var GREEN = "#59a14f", RED = "#d62728", MIXED = "#e69f00";

  function esc(s) {
    return String(s).replace(/&/g, "&amp;").replace(/</g, "&lt;")
      .replace(/>/g, "&gt;").replace(/"/g, "&quot;");
  }
  function num(v) {
    var s = v.toFixed(6).replace(/0+$/, "").replace(/\.$/, "");
    return s === "-0" ? "0" : s;
  }
  function anchor(name) {
    return String(name).replace(/[^A-Za-z0-9_-]/g, "_");
  }
  // First index whose time is >= t.
  function lower(times, t) {
    var lo = 0, hi = times.length;
    while (lo < hi) {
      var mid = (lo + hi) >> 1;
      if (times[mid] < t) lo = mid + 1; else hi = mid;
    }
    return lo;
  }
  // First index whose time is > t.
  function upper(times, t) {
    var lo = 0, hi = times.length;
    while (lo < hi) {
      var mid = (lo + hi) >> 1;
      if (times[mid] <= t) lo = mid + 1; else hi = mid;
    }
    return lo;
  }
  function niceStep(span, ticks) {
    var raw = Math.max(span / ticks, 1e-12);
    var mag = Math.pow(10, Math.floor(Math.log10(raw)));
    var m = raw / mag;
    return (m <= 1 ? 1 : m <= 2 ? 2 : m <= 5 ? 5 : 10) * mag;
  }

  // A property's verdict at point k: the report's columns are strings of 1 and 0, the
  // live page's arrays of the sidecar's words (true, currently_true, ..., unknown).
  function verdictAt(col, k) {
    if (typeof col !== "string") return col[k];
    var c = col.charCodeAt(k);
    return c === 49 ? "true" : c === 48 ? "false" : "unknown";
  }
  var VERDICT_FILL = { "true": GREEN, "false": RED, currently_true: "#8fd694",
    currently_false: "#f08a8a", unknown: "#bbbbbb" };
  function isFalse(v) { return v === "false" || v === "currently_false"; }

  // Point k is the last so far (points are added in order, and the last one may change
  // while its verdicts arrive): keeps lane.ch, the points where get(k) differs from the
  // point before (and point 0). A lane is drawn from these, so its cost is its number
  // of changes, not the run's number of points.
  function touch(lane, k) {
    var ch = lane.ch, last = ch.length > 0 && ch[ch.length - 1] === k, v = lane.get(k);
    var is = k === 0 || v !== lane.get(k - 1);
    if (is && !last) ch.push(k);
    else if (!is && last) ch.pop();
    if (lane.kind === "verdict") {
      if (lane.first === k && !isFalse(v)) lane.first = -1;
      if (lane.first < 0 && isFalse(v)) lane.first = k;
    } else if (lane.kind !== "messages") {
      // Numbers draw as steps, booleans as marks, anything else (or a mix) as text.
      if (typeof v === "number") {
        lane.nums = true;
        if (v < lane.min) lane.min = v;
        if (v > lane.max) lane.max = v;
      } else if (typeof v === "boolean") lane.bools = true;
      else lane.other = true;
      lane.kind = lane.other || (lane.nums && lane.bools) ? "text" : lane.nums ? "num" : "bool";
    }
  }

  function lanesOf(run) {
    var lanes = [{ kind: "messages", name: "messages", ch: [] }];
    run.vars.forEach(function (name, i) {
      var col = run.values[i];
      lanes.push({ kind: "bool", name: name, get: function (k) { return col[k]; }, min: Infinity,
        max: -Infinity, ch: [] });
    });
    run.verdict_names.forEach(function (name, j) {
      var col = run.verdicts;
      lanes.push({ kind: "verdict", name: name, first: -1, ch: [],
        get: function (k) { return verdictAt(col[j], k); } });
    });
    return lanes;
  }

  // A run's timeline in `el`, with its buttons in `tools` and the selected point's state
  // in `state`. `opts.follow`: the view keeps the run's end in sight as points are added
  // (`grow`); zooming or panning stops that, the "follow" button starts it again.
  function Timeline(el, run, tools, state, opts) {
    this.el = el;
    this.run = run;
    this.tools = tools;
    this.state = state;
    this.follow = !!(opts && opts.follow);
    this.sel = -1;
    // Points dropped from the front (the live page's cap): shown numbers count from the
    // run's first point, not from the first one kept.
    this.base = 0;
    this.pinned = false;
    this.lanes = lanesOf(run);
    // The two kinds of point the message lane marks (the report's sends and receives, the
    // live page's samples and requests).
    var kinds = run.message_kinds || ["send", "receive"];
    this.sendName = run.names.indexOf(kinds[0]);
    this.receiveName = run.names.indexOf(kinds[1]);
    // Sends and receives before each point, so a pixel asks "any message here?" in O(log n).
    this.sends = [0];
    this.receives = [0];
    this.sendIdx = [];
    this.n = 0;
    this.grow();
    this.view = [this.t0, this.tEnd];
    this.height = AXIS + this.lanes.length * LANE + PAD;
    this.measure();
    this.bind();
    var t = performance.now();
    this.draw();
    this.drawMs = performance.now() - t;
    if (state && this.sendIdx.length > 0) {
      this.seqEl = document.createElement("div");
      this.seqEl.className = "seq";
      state.parentNode.insertBefore(this.seqEl, state.nextSibling);
      this.drawSequence();
    }
    this.tree = new Tree(run);
    if (this.tree.count > 0 && state) {
      this.treeEl = document.createElement("div");
      this.treeEl.className = "bt";
      var after = this.seqEl || state;
      after.parentNode.insertBefore(this.treeEl, after.nextSibling);
      this.drawTree();
    }
  }

  // Takes in the points added to the run's columns since the last call (and the last
  // point again: its verdicts may have changed), then redraws on the next frame.
  Timeline.prototype.grow = function () {
    var run = this.run, to = run.time.length, from = Math.max(this.n - 1, 0);
    var send = run.names.indexOf("send"), lanes = this.lanes;
    for (var k = from; k < to; k++) {
      for (var i = 1; i < lanes.length; i++) touch(lanes[i], k);
      if (k < this.n) continue;
      this.sends.push(this.sends[k] + (run.step[k] === this.sendName ? 1 : 0));
      this.receives.push(this.receives[k] + (run.step[k] === this.receiveName ? 1 : 0));
      if (run.step[k] === send) this.sendIdx.push(k);
    }
    var oldEnd = this.tEnd, whole = this.view && this.view[0] <= this.t0 && this.view[1] >= oldEnd;
    this.n = to;
    this.t0 = to ? run.time[0] : 0;
    this.tEnd = to ? Math.max(run.time[to - 1], this.t0 + 1) : 1;
    if (!this.view) return;
    if (this.follow) {
      var span = this.view[1] - this.view[0];
      this.view = whole ? [this.t0, this.tEnd] : [Math.max(this.tEnd - span, this.t0), this.tEnd];
      if (!this.pinned) this.sel = to - 1;
    }
    this.schedule();
  };
  // Forgets the run's first `count` points (the live page keeps only its last ones, so a
  // sidecar running for days does not fill the browser's memory): the columns lose them
  // and the lanes are rebuilt from the points kept, so a point's index shifts by `count`.
  // O(points kept); the live page drops in chunks, so that is a few steps per point.
  Timeline.prototype.dropFront = function (count) {
    var run = this.run, view = this.view;
    count = Math.min(count, run.time.length);
    if (count <= 0) return;
    [run.time, run.step, run.event, run.origin, run.target, run.params].concat(run.values, run.verdicts)
      .forEach(function (col) { col.splice(0, count); });
    this.lanes = lanesOf(run);
    this.sends = [0];
    this.receives = [0];
    this.sendIdx = [];
    this.sel -= count;
    this.base += count;
    if (this.sel < 0) { this.sel = -1; this.pinned = false; }
    this.n = 0;
    this.view = null;
    this.grow();
    // A view that began before the points kept starts at the first of them.
    this.view = view;
    if (view[0] < this.t0) this.setView(this.t0, Math.max(view[1], this.t0 + 1));
  };
  Timeline.prototype.schedule = function () {
    var self = this;
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(function () {
      self.pending = false;
      self.draw();
      if (self.sel >= 0) self.showState();
      if (self.onDrawn) self.onDrawn();
    });
  };
  Timeline.prototype.setFollow = function (on) {
    this.follow = on;
    this.el.setAttribute("data-follow", on ? "on" : "off");
    var b = this.tools && this.tools.querySelector("[data-act=follow]");
    if (b) b.className = on ? "on" : "";
    if (on) {
      var span = this.view[1] - this.view[0];
      this.setView(this.tEnd - span, this.tEnd);
      this.draw();
    }
  };

  // The drawing width, read once per draw (reading layout per point would be slow).
  Timeline.prototype.measure = function () {
    this.w = Math.max(this.el.clientWidth || 0, 400);
  };
  Timeline.prototype.width = function () {
    return this.w;
  };
  Timeline.prototype.x = function (t) {
    var w = this.width() - LABEL - RIGHT;
    return LABEL + (t - this.view[0]) / (this.view[1] - this.view[0]) * w;
  };
  Timeline.prototype.t = function (x) {
    var w = this.width() - LABEL - RIGHT;
    return this.view[0] + (x - LABEL) / w * (this.view[1] - this.view[0]);
  };
  Timeline.prototype.timeText = function (t) {
    var s = this.run.step_seconds;
    return s ? num(t * s) + " s" : String(t);
  };

  // Bands of equal value; sub-pixel stretches merge into one band of colour `mixed`.
  Timeline.prototype.bands = function (lane, y, h, colour, mixed, lo, hi) {
    var out = [], cur = null, time = this.run.time, self = this;
    var L = LABEL, R = this.width() - RIGHT;
    function flush() {
      if (!cur) return;
      var c = cur.mixed ? mixed : colour(cur.v);
      if (c) {
        var w = Math.max(cur.x1 - cur.x0, 1.5);
        out.push('<rect x="' + cur.x0.toFixed(1) + '" y="' + y + '" width="' + w.toFixed(1) +
          '" height="' + h + '" fill="' + c + '"/>');
      }
      if (lane.kind === "text" && !cur.mixed && cur.x1 - cur.x0 > 8 * String(cur.v).length) {
        out.push('<text class="tick" x="' + (cur.x0 + 3).toFixed(1) + '" y="' + (y + h - 5) + '">' +
          esc(cur.v) + "</text>");
      }
    }
    var ch = lane.ch;
    for (var j = Math.max(upper(ch, lo) - 1, 0); j < ch.length && ch[j] < hi; j++) {
      var k = ch[j], next = j + 1 < ch.length ? ch[j + 1] : self.n;
      var v = lane.get(k);
      var xa = Math.max(self.x(time[k]), L);
      var xb = Math.min(self.x(next < self.n ? time[next] : self.tEnd), R);
      if (xb < L || xa > R) continue;
      if (cur && cur.v === v && !cur.mixed) {
        cur.x1 = Math.max(cur.x1, xb);
      } else if (cur && cur.x1 - cur.x0 < 1 && xb - cur.x0 < 2) {
        cur.mixed = true;
        cur.x1 = Math.max(cur.x1, xb);
      } else {
        flush();
        cur = { v: v, x0: xa, x1: xb, mixed: false };
      }
    }
    flush();
    return out.join("");
  };

  // A number lane as a step line; points sharing a pixel draw their range as one stroke.
  Timeline.prototype.steps = function (lane, y, h, lo, hi) {
    var time = this.run.time, span = lane.max - lane.min, d = "", last = null;
    var ymin = 0, ymax = 0, ylast = 0, R = this.width() - RIGHT;
    function Y(v) {
      return span > 0 ? y + h - 2 - (v - lane.min) / span * (h - 4) : y + h / 2;
    }
    var ch = lane.ch;
    for (var j = Math.max(upper(ch, lo) - 1, 0); j < ch.length && ch[j] < hi; j++) {
      var k = ch[j];
      var px = Math.round(Math.min(Math.max(this.x(time[k]), LABEL), R));
      var yy = Y(lane.get(k));
      if (px === last) {
        ymin = Math.min(ymin, yy);
        ymax = Math.max(ymax, yy);
        ylast = yy;
        continue;
      }
      if (last === null) d = "M" + px + " " + yy.toFixed(1);
      else d += "V" + ymin.toFixed(1) + "V" + ymax.toFixed(1) + "V" + ylast.toFixed(1) + "H" + px;
      last = px;
      ymin = ymax = ylast = yy;
    }
    if (last === null) return "";
    d += "V" + ymin.toFixed(1) + "V" + ymax.toFixed(1) + "V" + ylast.toFixed(1) + "H" +
      Math.round(Math.min(this.x(this.tEnd), R));
    return '<path d="' + d + '" fill="none" stroke="#0072b2" stroke-width="1.5"/>';
  };

  // Message ticks: sends in the upper half, receives in the lower; one per pixel and kind.
  Timeline.prototype.ticks = function (y, h, lo, hi) {
    var time = this.run.time, step = this.run.step, seen = {}, d = ["", ""];
    var send = this.sendName, receive = this.receiveName;
    var R = this.width() - RIGHT;
    if (hi - lo > 2 * (R - LABEL)) {
      // More points than pixels: ask each pixel whether it holds a send or a receive.
      var counts = [this.sends, this.receives];
      for (var p = LABEL; p <= R; p++) {
        var a = lower(time, this.t(p - 0.5)), b = lower(time, this.t(p + 0.5));
        for (var c = 0; c < 2; c++) {
          if (counts[c][b] > counts[c][a]) {
            d[c] += "M" + p + " " + (y + 2 + c * (h / 2 - 1)).toFixed(1) + "v" + (h / 2 - 3).toFixed(1);
          }
        }
      }
      return '<path d="' + d[0] + '" stroke="#0072b2"/><path d="' + d[1] + '" stroke="#d55e00"/>';
    }
    for (var k = lo; k < hi; k++) {
      var s = step[k] === send ? 0 : step[k] === receive ? 1 : -1;
      if (s < 0) continue;
      var px = Math.round(this.x(time[k]));
      if (px < LABEL || px > this.width() - RIGHT) continue;
      var key = px * 2 + s;
      if (seen[key]) continue;
      seen[key] = true;
      var y0 = y + 2 + s * (h / 2 - 1);
      d[s] += "M" + px + " " + y0.toFixed(1) + "v" + (h / 2 - 3).toFixed(1);
    }
    return '<path d="' + d[0] + '" stroke="#0072b2"/><path d="' + d[1] + '" stroke="#d55e00"/>';
  };

  Timeline.prototype.axis = function () {
    var s = this.run.step_seconds || 1, out = [];
    var a = this.view[0] * s, b = this.view[1] * s;
    var step = niceStep(b - a, Math.max(2, Math.floor((this.width() - LABEL) / 90)));
    for (var v = Math.ceil(a / step) * step; v <= b + step * 1e-9; v += step) {
      var x = this.x(v / s).toFixed(1);
      out.push('<line x1="' + x + '" x2="' + x + '" y1="' + (AXIS - 4) + '" y2="' + this.height +
        '" stroke="#eee"/><text class="tick" x="' + x + '" y="' + (AXIS - 8) +
        '" text-anchor="middle">' + num(v) + "</text>");
    }
    out.push('<text class="tick" x="4" y="' + (AXIS - 8) + '">time (' +
      (this.run.step_seconds ? "s" : "steps") + ")</text>");
    return out.join("");
  };

  Timeline.prototype.draw = function () {
    this.measure();
    var W = this.width(), time = this.run.time, self = this;
    var lo = Math.max(lower(time, this.view[0]) - 1, 0);
    var hi = Math.min(upper(time, this.view[1]) + 1, this.n);
    var parts = ['<svg width="' + W + '" height="' + this.height + '">', this.axis()];
    this.lanes.forEach(function (lane, i) {
      var y = AXIS + i * LANE, h = LANE - 6;
      parts.push('<g class="lane" data-kind="' + lane.kind + '" data-name="' + esc(lane.name) + '">');
      parts.push('<rect x="0" y="' + y + '" width="' + W + '" height="' + (LANE - 2) + '" fill="' +
        (i % 2 ? "#fff" : "#f6f6f6") + '"/>');
      var label = esc(lane.name);
      if (lane.kind === "num") label += " (" + num(lane.min) + " to " + num(lane.max) + ")";
      if (lane.kind === "verdict") {
        label = '<a href="#prop-' + anchor(lane.name) + '">' + label + "</a>";
      }
      parts.push('<text class="lbl' + (lane.kind === "verdict" ? " verdict" : "") + '" x="4" y="' +
        (y + h - 2) + '">' + label + "</text>");
      var yb = y + 2;
      if (lane.kind === "messages") parts.push(self.ticks(yb, h, lo, hi));
      else if (lane.kind === "num") parts.push(self.steps(lane, yb, h, lo, hi));
      else if (lane.kind === "bool") {
        var blue = "#0072b2";
        parts.push(self.bands(lane, yb + 3, h - 6, function (v) { return v ? blue : null; }, blue, lo, hi));
      } else if (lane.kind === "text") {
        var pal = ["#dbe9f6", "#fde7d0"], seen = {}, n = 0;
        parts.push(self.bands(lane, yb, h, function (v) {
          if (!(v in seen)) seen[v] = pal[n++ % 2];
          return seen[v];
        }, "#bbb", lo, hi));
      } else {
        parts.push(self.bands(lane, yb, h, function (v) { return VERDICT_FILL[v] || "#bbbbbb"; }, MIXED,
          lo, hi));
        if (lane.first >= 0) {
          var ft = time[lane.first], fx = self.x(ft);
          if (fx >= LABEL - 1 && fx <= W - RIGHT + 1) {
            parts.push('<a href="#prop-' + anchor(lane.name) + '"><g class="ff-mark" data-property="' +
              esc(lane.name) + '" data-time="' + ft + '" data-point="' + lane.first + '"><line x1="' +
              fx.toFixed(1) + '" x2="' + fx.toFixed(1) + '" y1="' + AXIS + '" y2="' + (y + LANE) +
              '" stroke="' + RED + '" stroke-dasharray="3 2"/><path d="M' + fx.toFixed(1) + " " + y +
              "l-5 -6h10z" + '" fill="' + RED + '"/><title>' + esc(lane.name) + " is false from t = " +
              self.timeText(ft) + " (point " + lane.first + ")</title></g></a>");
          }
        }
      }
      parts.push("</g>");
    });
    if (this.sel >= 0) {
      var sx = this.x(time[this.sel]);
      if (sx >= LABEL && sx <= W - RIGHT) {
        parts.push('<line class="cursor" x1="' + sx.toFixed(1) + '" x2="' + sx.toFixed(1) + '" y1="' +
          AXIS + '" y2="' + this.height + '" stroke="#333" stroke-width="' + (this.pinned ? 2 : 1) + '"/>');
      }
    }
    parts.push("</svg>");
    this.el.innerHTML = parts.join("");
    var view = this.tools && this.tools.querySelector(".view");
    if (view) {
      view.textContent = "showing " + this.timeText(this.view[0]) + " to " + this.timeText(this.view[1]) +
        " (points " + (this.base + lower(time, this.view[0])) + " to " +
        (this.base + Math.max(upper(time, this.view[1]) - 1, 0)) + " of " + (this.base + this.n) + ")";
    }
  };

  Timeline.prototype.showState = function () {
    var r = this.run, k = this.sel, nm = r.names;
    if (k < 0 || !this.state) return;
    var rows = [["point", (this.base + k) + " of " + (this.base + this.n) + (this.pinned ? " (pinned)" : "")],
      ["time", this.timeText(r.time[k])], ["step", nm[r.step[k]]]];
    if (nm[r.event[k]]) {
      var from = nm[r.origin[k]], to = nm[r.target[k]];
      rows.push(["message", nm[r.event[k]] + (from || to ? ": " + from + " \u2192 " + to : "")]);
    }
    if (r.params[k]) rows.push(["parameters", r.params[k]]);
    var html = "<table><tbody>";
    rows.forEach(function (row) {
      html += "<tr><th>" + esc(row[0]) + "</th><td>" + esc(row[1]) + "</td></tr>";
    });
    r.vars.forEach(function (name, i) {
      html += "<tr><th>" + esc(name) + "</th><td>" + esc(r.values[i][k]) + "</td></tr>";
    });
    r.verdict_names.forEach(function (name, j) {
      var v = verdictAt(r.verdicts[j], k);
      html += '<tr><th><a href="#prop-' + anchor(name) + '">' + esc(name) + '</a></th><td class="' +
        (isFalse(v) ? "f" : v === "unknown" ? "u" : "t") + '">' + esc(v) + "</td></tr>";
    });
    this.state.innerHTML = html + "</tbody></table>";
  };

  // The behavior tree of a robot model, read from the run's own messages: the lowering
  // names each node's machine BT_plugin_<id>_<type>, a parent sends bt_<id>_tick and
  // bt_<id>_halt, the node answers bt_<id>_response with status 1 SUCCESS, 2 FAILURE,
  // 3 RUNNING (crates/robot/src/bt/control.rs). A node's status at a point is its last
  // such message: ticked (waiting for its answer), its answer, or idle after a halt.
  var BT_STATUS = { 1: "success", 2: "failure", 3: "running" };
  var BT_FILL = { idle: "#eeeeee", ticked: "#fff3b0", success: "#8fd694", failure: "#f08a8a", running: "#f6c26b" };
  var BT_MARK = { Sequence: "\u2192", ReactiveSequence: "R\u2192", SequenceWithMemory: "M\u2192",
    Fallback: "?", ReactiveFallback: "R?", Parallel: "\u21c9", Inverter: "!" };

  function Tree(run) {
    var ev = [], self = this;
    run.names.forEach(function (name, i) {
      var m = /^bt_(\d+)_(tick|response|halt)$/.exec(name);
      if (m) ev[i] = { id: m[1], kind: m[2] };
    });
    var send = run.names.indexOf("send"), nodes = {}, order = [];
    function node(id) {
      if (!nodes[id]) {
        nodes[id] = { id: id, type: "?", children: [], parent: null, at: [], status: [] };
        order.push(id);
      }
      return nodes[id];
    }
    for (var k = 0; k < run.time.length; k++) {
      var e = ev[run.event[k]];
      if (!e || run.step[k] !== send) continue;
      var n = node(e.id);
      if (e.kind === "response") {
        var st = /(?:^|;)status=(\d+)/.exec(run.params[k]);
        n.at.push(k);
        n.status.push(st && BT_STATUS[st[1]] || "ticked");
        continue;
      }
      var tm = /^BT_plugin_\d+_(.+)$/.exec(run.names[run.target[k]]);
      if (tm) n.type = tm[1];
      var pm = /^BT_plugin_(\d+)_/.exec(run.names[run.origin[k]]);
      if (pm && n.parent === null) {
        n.parent = pm[1];
        node(pm[1]).children.push(e.id);
      }
      n.at.push(k);
      n.status.push(e.kind === "tick" ? "ticked" : "idle");
    }
    this.nodes = nodes;
    this.roots = order.filter(function (id) { return nodes[id].parent === null; }).sort();
    order.forEach(function (id) {
      nodes[id].children.sort(function (a, b) { return Number(a) - Number(b); });
    });
    this.count = order.length;
    // Layout: leaves in order left to right, a parent centred over its children.
    var slot = 0, depth = 0;
    function place(id, d) {
      var n = nodes[id];
      n.depth = d;
      depth = Math.max(depth, d);
      if (n.children.length === 0) {
        n.x = slot++;
      } else {
        n.children.forEach(function (c) { place(c, d + 1); });
        n.x = (nodes[n.children[0]].x + nodes[n.children[n.children.length - 1]].x) / 2;
      }
    }
    this.roots.forEach(function (r) { place(r, 0); });
    this.slots = slot;
    this.depth = depth;
    this.statusAt = function (id, k) {
      var n = self.nodes[id], i = upper(n.at, k) - 1;
      return i < 0 ? "idle" : n.status[i];
    };
  }

  Tree.prototype.svg = function (k) {
    var BW = 124, BH = 34, GX = 10, GY = 30, nodes = this.nodes, self = this;
    var W = this.slots * (BW + GX) + GX, H = (this.depth + 1) * (BH + GY) + GY;
    var out = ['<svg width="' + W + '" height="' + H + '">'];
    function cx(n) { return GX + n.x * (BW + GX) + BW / 2; }
    function cy(n) { return GY + n.depth * (BH + GY); }
    Object.keys(nodes).forEach(function (id) {
      var n = nodes[id];
      n.children.forEach(function (c) {
        var m = nodes[c];
        out.push('<path d="M' + cx(n) + " " + (cy(n) + BH) + "V" + (cy(n) + BH + GY / 2) + "H" + cx(m) +
          "V" + cy(m) + '" fill="none" stroke="#888"/>');
      });
    });
    Object.keys(nodes).forEach(function (id) {
      var n = nodes[id], st = self.statusAt(id, k), mark = BT_MARK[n.type];
      var label = mark ? mark + " " + n.type : n.type;
      if (label.length > 21) label = label.slice(0, 20) + "\u2026";
      var control = n.children.length > 0;
      out.push('<g class="bt-node" data-node="' + esc(id) + '" data-status="' + st + '"><rect x="' +
        (cx(n) - BW / 2) + '" y="' + cy(n) + '" width="' + BW + '" height="' + BH + '" rx="' +
        (control ? 2 : 10) + '" fill="' + BT_FILL[st] + '" stroke="#555"/><text class="lbl" x="' + cx(n) +
        '" y="' + (cy(n) + 14) + '" text-anchor="middle">' + esc(label) +
        '</text><text class="tick" x="' + cx(n) + '" y="' + (cy(n) + 27) + '" text-anchor="middle">' +
        st + " (" + esc(id) + ")</text><title>" + esc(n.type + " " + id + ": " + st) + "</title></g>");
    });
    out.push("</svg>");
    return out.join("");
  };

  // The messages around the selected point as a sequence chart: one lifeline per machine
  // that sends or receives in the window, one arrow per send (SEQ_AROUND before and
  // after the selection), the send at or before the selection highlighted.
  var SEQ_AROUND = 20;
  Timeline.prototype.drawSequence = function () {
    if (!this.seqEl) return;
    var r = this.run, nm = r.names, send = nm.indexOf("send"), k = Math.max(this.sel, 0);
    var at = upper(this.sendIdx, k) - 1;
    var from = Math.max(at - SEQ_AROUND + 1, 0), to = Math.min(at + SEQ_AROUND + 1, this.sendIdx.length);
    var rows = this.sendIdx.slice(from, to), lanes = [], col = {};
    rows.forEach(function (p) {
      [r.origin[p], r.target[p]].forEach(function (m) {
        if (!(m in col)) { col[m] = lanes.length; lanes.push(m); }
      });
    });
    if (send < 0 || rows.length === 0) { this.seqEl.innerHTML = ""; return; }
    var CW = 150, RH = 20, TOP = 34, W = lanes.length * CW + 20, H = TOP + rows.length * RH + 10;
    function lx(m) { return 10 + col[m] * CW + CW / 2; }
    var out = ['<svg width="' + W + '" height="' + H + '">'];
    lanes.forEach(function (m) {
      var name = nm[m], short = name.length > 22 ? name.slice(0, 21) + "\u2026" : name;
      out.push('<text class="lbl" x="' + lx(m) + '" y="14" text-anchor="middle">' + esc(short) +
        "<title>" + esc(name) + '</title></text><line x1="' + lx(m) + '" x2="' + lx(m) + '" y1="' + 20 +
        '" y2="' + H + '" stroke="#bbb" stroke-dasharray="4 3"/>');
    });
    var self = this;
    rows.forEach(function (p, i) {
      var y = TOP + i * RH + RH / 2, x1 = lx(r.origin[p]), x2 = lx(r.target[p]);
      var mine = from + i === at, dir = x2 >= x1 ? 1 : -1;
      if (mine) {
        out.push('<rect x="0" y="' + (y - RH / 2) + '" width="' + W + '" height="' + RH + '" fill="#fff3b0"/>');
      }
      var line = x1 === x2
        ? '<path d="M' + x1 + " " + (y - 4) + "h18v8h-14" + '" fill="none" stroke="#333"/>'
        : '<line x1="' + x1 + '" x2="' + (x2 - dir * 6) + '" y1="' + y + '" y2="' + y + '" stroke="#333"/>' +
          '<path d="M' + x2 + " " + y + "l" + (-dir * 7) + " -4v8z" + '" fill="#333"/>';
      var label = nm[r.event[p]] + (r.params[p] ? " (" + r.params[p] + ")" : "");
      if (label.length > 60) label = label.slice(0, 59) + "\u2026";
      out.push('<g class="seq-msg' + (mine ? " selected" : "") + '" data-point="' + p + '">' + line +
        '<text class="tick" x="' + (Math.min(x1, x2) + 4) + '" y="' + (y - 3) + '">' + esc(label) +
        "</text><title>point " + p + ", t = " + esc(self.timeText(r.time[p])) + ": " + esc(nm[r.event[p]]) +
        " " + esc(nm[r.origin[p]]) + " \u2192 " + esc(nm[r.target[p]]) + "</title></g>");
    });
    out.push("</svg>");
    this.seqEl.innerHTML = "<p><b>Messages</b> around point " + k + " (" + rows.length +
      " sends; the highlighted one is the last at or before the point)</p>" + out.join("");
  };

  Timeline.prototype.drawTree = function () {
    if (!this.tree || this.tree.count === 0 || !this.treeEl) return;
    var k = Math.max(this.sel, 0);
    this.treeEl.innerHTML = "<p><b>Behavior tree</b> at point " + k + " (t = " +
      this.timeText(this.run.time[k] || 0) + "): " +
      Object.keys(BT_FILL).map(function (s) {
        return '<span class="bt-key" style="background:' + BT_FILL[s] + '">' + s + "</span>";
      }).join(" ") + "</p>" + this.tree.svg(k);
  };

  Timeline.prototype.select = function (k, pin) {
    if (this.n === 0) return;
    this.sel = Math.min(Math.max(k, 0), this.n - 1);
    this.pinned = pin;
    var t = this.run.time[this.sel], span = this.view[1] - this.view[0];
    if (t < this.view[0] || t > this.view[1]) this.setView(t - span / 2, t + span / 2);
    this.draw();
    this.showState();
    this.drawSequence();
    this.drawTree();
  };
  Timeline.prototype.at = function (x) {
    return Math.max(upper(this.run.time, this.t(x)) - 1, 0);
  };
  Timeline.prototype.setView = function (a, b) {
    var full = this.tEnd - this.t0, span = Math.min(Math.max(b - a, 1), full);
    a = Math.min(Math.max(a, this.t0), this.tEnd - span);
    this.view = [a, a + span];
  };
  Timeline.prototype.zoom = function (factor, around) {
    var a = this.view[0], b = this.view[1];
    if (this.follow) this.setFollow(false);
    if (around === undefined) around = (a + b) / 2;
    this.setView(around - (around - a) * factor, around + (b - around) * factor);
    this.draw();
  };
  // Zooms to a twentieth of the run (at least 20 steps) around point k and pins it.
  Timeline.prototype.focusPoint = function (k) {
    if (this.n === 0) return;
    k = Math.min(Math.max(k, 0), this.n - 1);
    var t = this.run.time[k], span = Math.max((this.tEnd - this.t0) / 20, 20);
    if (this.follow) this.setFollow(false);
    this.setView(t - span / 2, t + span / 2);
    this.select(k, true);
  };
  Timeline.prototype.toFirstFalse = function () {
    var run = this.run, want = run.property, best = -1;
    this.lanes.forEach(function (l) {
      if (l.kind === "verdict" && l.first >= 0 && (best < 0 || l.name === want)) best = l.first;
    });
    if (best >= 0) this.focusPoint(best);
  };

  Timeline.prototype.bind = function () {
    var self = this, el = this.el, drag = null;
    function localX(e) { return e.clientX - el.getBoundingClientRect().left; }
    el.addEventListener("wheel", function (e) {
      e.preventDefault();
      self.zoom(e.deltaY > 0 ? 1.25 : 0.8, self.t(localX(e)));
    }, { passive: false });
    el.addEventListener("mousedown", function (e) {
      drag = { x: localX(e), view: self.view.slice(), moved: false };
    });
    window.addEventListener("mouseup", function (e) {
      if (!drag) return;
      var d = drag;
      drag = null;
      if (!d.moved && e.target && el.contains(e.target) && localX(e) >= LABEL) {
        var k = self.at(localX(e));
        self.select(k, !(self.pinned && k === self.sel));
      }
    });
    el.addEventListener("mousemove", function (e) {
      var x = localX(e);
      if (drag) {
        var dx = x - drag.x;
        if (Math.abs(dx) > 3 && !drag.moved) {
          drag.moved = true;
          if (self.follow) self.setFollow(false);
        }
        if (drag.moved) {
          var per = (drag.view[1] - drag.view[0]) / (self.width() - LABEL - RIGHT);
          self.setView(drag.view[0] - dx * per, drag.view[1] - dx * per);
          self.draw();
        }
      } else if (!self.pinned && x >= LABEL) {
        self.select(self.at(x), false);
      }
    });
    el.addEventListener("keydown", function (e) {
      if (e.key === "ArrowRight" || e.key === "ArrowLeft") {
        e.preventDefault();
        self.select(self.sel + (e.key === "ArrowRight" ? 1 : -1), true);
      } else if (e.key === "+" || e.key === "=") self.zoom(0.8);
      else if (e.key === "-") self.zoom(1.25);
    });
    if (this.tools) {
      this.tools.addEventListener("click", function (e) {
        var act = e.target && e.target.getAttribute("data-act");
        if (act === "fit") { self.setView(self.t0, self.tEnd); self.draw(); }
        else if (act === "in") self.zoom(0.5);
        else if (act === "out") self.zoom(2);
        else if (act === "false") self.toFirstFalse();
        else if (act === "follow") self.setFollow(true);
      });
    }
    window.addEventListener("resize", function () { self.draw(); });
  };

  // The report: every saved failing run, drawn once.
  function report(data) {
    var start = performance.now();
    var runs = JSON.parse(data.textContent);
    var drawn = 0, drawMs = 0;
    runs.forEach(function (run, i) {
      var el = document.getElementById("timeline-" + i);
      if (!el) return;
      var section = document.getElementById("run-" + i);
      var tl = new Timeline(el, run, section && section.querySelector(".tools"),
        document.getElementById("state-" + i));
      el.hindsightTimeline = tl;
      drawn += 1;
      drawMs = Math.max(drawMs, tl.drawMs);
    });
    // `#run-I-point-K` (the first false points link there) selects point K of run I.
    function fromHash() {
      var m = /^#run-(\d+)-point-(\d+)$/.exec(window.location.hash);
      var el = m && document.getElementById("timeline-" + m[1]);
      if (el && el.hindsightTimeline) {
        el.hindsightTimeline.focusPoint(Number(m[2]));
        el.scrollIntoView();
      }
    }
    window.addEventListener("hashchange", fromHash);
    fromHash();
    var now = performance.now();
    body.setAttribute("data-rendered", String(drawn));
    // Milliseconds reading and drawing the timelines, the longest single draw (what a zoom
    // or pan at that view costs), and from navigation start to here (page parsed).
    body.setAttribute("data-render-ms", (now - start).toFixed(1));
    body.setAttribute("data-draw-ms", drawMs.toFixed(1));
    body.setAttribute("data-ready-ms", now.toFixed(1));
  }

  var runs = document.getElementById("hindsight-runs");
  if (runs) report(runs);
  // What the live page's script (`live/page_live.js`, inlined after this one) builds on.
  window.hindsight = { Timeline: Timeline, esc: esc, num: num, anchor: anchor, isFalse: isFalse };
})();
