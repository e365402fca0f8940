// hindsight monitor --serve: the live page's script. It feeds one timeline of the report's
// script (`report/page.js`, inlined before this one, which hands over `window.hindsight`)
// point by point from the sidecar's event stream.
"use strict";
(function () {
  var h = window.hindsight;
  var Timeline = h.Timeline, esc = h.esc, num = h.num, anchor = h.anchor, isFalse = h.isFalse;

  // The live page (`monitor --serve`): the sidecar's inputs and verdict lines arrive as
  // server-sent events in the order it wrote them. Each input is a point (its variables'
  // values carried from the point before, an event true only at its point); the verdict
  // lines after it are that point's verdicts, carried to the points after it.
  function live(data) {
    var spec = JSON.parse(data.textContent), props = spec.properties, vars = spec.vars;
    var run = { name: "live", property: null, run: null, step_seconds: spec.unit_ns / 1e9,
      vars: vars.map(function (v) { return v.name; }), verdict_names: props, time: [],
      names: ["sample", "request", ""], message_kinds: ["sample", "request"], step: [], event: [],
      origin: [], target: [], params: [], values: vars.map(function () { return []; }),
      verdicts: props.map(function () { return []; }) };
    var ids = {}, index = {}, rows = {}, now = vars.map(function (v) { return v.init; });
    var verdict = props.map(function () { return "unknown"; });
    var lines = 0, lastTime = 0, delays = [], waiting = [];
    // The page keeps the last `keep` points (`?keep=N` sets it): more would fill the
    // browser's memory when a sidecar runs for days. Past it, the oldest eighth goes at
    // once, so the lanes are rebuilt once per keep / 8 points. The verdict table does
    // not read the points (each row keeps its first false time from the verdict lines),
    // so it stays whole; the timeline's first-false mark is the first among the points kept.
    var keep = 200000, dropped = 0, skipped = 0;
    var asked = /[?&]keep=(\d+)/.exec(window.location.search);
    if (asked && Number(asked[1]) > 0) keep = Number(asked[1]);
    function intern(s) {
      if (!(s in ids)) { ids[s] = run.names.length; run.names.push(s); }
      return ids[s];
    }
    run.names.forEach(function (s, i) { ids[s] = i; });
    function text(id, v) { document.getElementById(id).textContent = v; }
    function seconds(t) { return num(t * spec.unit_ns / 1e9) + " s"; }
    props.forEach(function (p, j) {
      index[p] = j;
      var tr = document.createElement("tr");
      tr.id = "prop-" + anchor(p);
      tr.setAttribute("data-property", p);
      tr.innerHTML = "<td><b>" + esc(p) + "</b></td><td><span class=\"badge v-none\">none</span></td>" +
        "<td class=\"since\">-</td><td class=\"ff\">-</td>";
      document.getElementById("rows").appendChild(tr);
      rows[p] = tr;
    });
    var el = document.getElementById("timeline-live");
    var tl = new Timeline(el, run, document.querySelector(".tools"), document.getElementById("state-live"),
      { follow: true });
    el.hindsightTimeline = tl;
    tl.setFollow(true);
    var note = document.createElement("p");
    note.className = "help";
    note.id = "kept";
    note.hidden = true;
    tl.tools.parentNode.insertBefore(note, tl.tools);
    function bound() {
      if (run.time.length <= keep) return;
      // The last point stays: the verdict lines that follow it are its verdicts.
      var count = Math.min(run.time.length - keep + Math.floor(keep / 8), run.time.length - 1);
      tl.dropFront(count);
      dropped += count;
      el.setAttribute("data-dropped", String(dropped));
      notice();
    }
    function notice() {
      var parts = [];
      if (dropped) {
        parts.push("Showing the last " + keep + " points at most (" + dropped +
          " older ones dropped from this page, so that it does not fill the browser's memory).");
      }
      if (skipped) {
        parts.push(skipped + " lines were older than the server's history when this page connected" +
          " and are not shown.");
      }
      parts.push("The full record is in the input log (--record) and the verdict file.");
      note.textContent = parts.join(" ");
      note.hidden = !(dropped || skipped);
    }
    function point(time, kind, source, params, sets) {
      run.time.push(time);
      run.step.push(intern(kind));
      run.event.push(intern(source || ""));
      run.origin.push(ids[""]);
      run.target.push(ids[""]);
      run.params.push(params);
      vars.forEach(function (v, i) {
        var x = sets && Object.prototype.hasOwnProperty.call(sets, v.name) ? sets[v.name]
          : v.event ? false : now[i];
        now[i] = x;
        run.values[i].push(x);
      });
      verdict.forEach(function (w, j) { run.verdicts[j].push(w); });
      if (time > lastTime) lastTime = time;
    }
    function input(r) {
      if (r.kind === "sample" || r.kind === "request") {
        point(r.time, r.kind, r.source, r.filter ? "may not falsify: " + r.filter.join(", ") : "", r.sets);
      } else if (r.kind === "tick") point(r.time, "tick", "", "", null);
      else if (r.kind === "loss") {
        point(r.time, "loss", r.source, r.count + " lost (" + r.reason + "): " + r.vars.join(", "), null);
      } else if (r.kind === "restart") point(r.time, "restart", r.source, "gap " + r.gap, null);
    }
    function judged(v) {
      var j = index[v.property], tr = rows[v.property];
      if (j === undefined) return;
      if (run.time.length === 0) point(v.time, "tick", "", "", null);
      verdict[j] = v.verdict;
      run.verdicts[j][run.time.length - 1] = v.verdict;
      tr.setAttribute("data-verdict", v.verdict);
      var badge = tr.querySelector(".badge");
      badge.className = "badge v-" + v.verdict;
      badge.textContent = v.verdict;
      tr.querySelector(".since").textContent = seconds(v.time);
      if (isFalse(v.verdict) && !tr.hasAttribute("data-first-false")) {
        tr.setAttribute("data-first-false", String(v.time * spec.unit_ns / 1e9));
        tr.querySelector(".ff").textContent = seconds(v.time);
      }
      if (v.time > lastTime) lastTime = v.time;
    }
    // The delay from the sidecar writing a verdict line to the frame that draws it (for
    // the lines written after the page opened: older ones come from the server's history).
    tl.onDrawn = function () {
      var t = Date.now();
      waiting.forEach(function (sent) { delays.push(Math.max(0, t - sent)); });
      waiting = [];
      if (delays.length > 10000) delays = delays.slice(-10000);
      text("lines", lines);
      text("points", run.time.length);
      text("last", seconds(lastTime));
      if (delays.length) {
        var s = delays.slice().sort(function (a, b) { return a - b; });
        text("delay-last", delays[delays.length - 1]);
        text("delay-median", s[Math.floor(s.length / 2)]);
        text("delay-max", s[s.length - 1]);
      }
    };
    var status = document.getElementById("status");
    var opened = Date.now(), lastId = "";
    // The browser reconnects by itself after a dropped stream, but not after an error
    // status (503 while the server has all the connections it takes): then a new stream
    // is opened after 2 s, resuming after the last event had (`?last=`, as
    // `Last-Event-ID`).
    function connect() {
      var es = new EventSource("/events" + (lastId ? "?last=" + encodeURIComponent(lastId) : ""));
      es.onopen = function () { status.textContent = "live"; status.className = ""; };
      es.onerror = function () {
        status.textContent = "reconnecting"; status.className = "down";
        if (es.readyState === 2) setTimeout(connect, 2000);
      };
      es.onmessage = message;
    }
    function message(e) {
      if (e.lastEventId) lastId = e.lastEventId;
      var m = JSON.parse(e.data);
      if (m.skipped) {
        skipped += m.skipped;
        el.setAttribute("data-skipped", String(skipped));
        notice();
      }
      if (m.input) input(m.input);
      if (m.verdict) {
        lines += 1;
        el.setAttribute("data-lines", String(lines));
        if (m.sent_ms >= opened) waiting.push(m.sent_ms);
        judged(m.verdict);
      }
      bound();
      tl.grow();
    }
    connect();
  }

  var spec = document.getElementById("hindsight-live");
  if (spec) live(spec);
})();
