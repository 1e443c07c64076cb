// The probe's live dashboard: takes the server's updates (server-sent
// events; the browser reconnects by itself and sends Last-Event-ID, so
// the server sends only what was missed) into bounded arrays and draws
// them with uPlot. Values a person reads come as text from the server,
// which applies the host's display rules (an undetermined azimuth is the
// word "undetermined", never a number; an invalid sigma is "n/a").
"use strict";

// Rows: sensors [t, gyro1, gyro2 (deg/s), a1x, a1y, a1z, a2x, a2y, a2z
// (m/s^2), gyro temp 1, accel temp 1, gyro temp 2, accel temp 2 (degC)];
// attitude [t, inc, inc sigma, azi, azi sigma, tf, tf sigma] (deg, null
// where undetermined or invalid).
const data = { recent: { sensors: [], attitude: [] }, long: { sensors: [], attitude: [] } };
let limits = { recent: 12000, long: 3600, bucket_s: 10 };
let view = "recent";
let dirty = true;

const $ = (id) => document.getElementById(id);

// This run's access token, which the server put in the page: commands
// carry it in a header, the event stream in its address.
const token = document.querySelector('meta[name="probe-token"]').content;

function setText(id, text) {
  const el = $(id);
  if (el && el.textContent !== String(text)) el.textContent = String(text);
}

// Appends rows, keeping at most `cap` (the oldest go).
function appendBounded(array, rows, cap) {
  for (const r of rows) array.push(r);
  if (array.length > cap) array.splice(0, array.length - cap);
}

function apply(update) {
  const rest = update.rest;
  if (rest.limits) limits = rest.limits;
  if (rest.reset) {
    data.recent.sensors = []; data.recent.attitude = [];
    data.long.sensors = []; data.long.attitude = [];
  }
  appendBounded(data.recent.sensors, update.sensors, limits.recent);
  appendBounded(data.recent.attitude, update.attitude, limits.recent);
  appendBounded(data.long.sensors, update.long_sensors, limits.long);
  appendBounded(data.long.attitude, update.long_attitude, limits.long);
  if (update.sensors.length || update.attitude.length || update.long_sensors.length || rest.reset) dirty = true;
  showState(rest);
}

function showAngle(id, text) {
  setText(id, text);
  // "undetermined" may carry its reason: "undetermined (heading lost ...)"
  $(id).className = text.startsWith("undetermined") ? "undetermined" : text === "n/a" ? "invalid" : "";
}

function showState(rest) {
  setText("source", rest.source.description);
  setText("status", rest.status);
  const l = rest.latest;
  if (l) {
    setText("time", l.time_s.toFixed(2) + " s");
    setText("mode", l.mode);
    setText("flags", l.flags.length ? l.flags.join(", ") : "none");
    showAngle("inclination", l.inclination);
    showAngle("azimuth", l.azimuth);
    showAngle("toolface", l.toolface);
    showAngle("roll", l.roll);
    showAngle("pitch", l.pitch);
  }
  const k = rest.link;
  setText("frames", `${k.frames} (raw ${k.raw}, navigation ${k.nav}, events ${k.events}, stations ${k.stations}, replies/other ${k.replies_and_unknown})`);
  setText("rate", k.rate_per_s === null ? "n/a (measuring)" : k.rate_per_s.toFixed(1) + " frames/s");
  setText("lost", k.lost);
  setText("crc", k.crc_errors);
  setText("malformed", k.malformed);
  setText("restarts", k.restarts);
  setText("garbage", k.garbage_bytes);
  setText("held", `${data.recent.sensors.length} samples, ${data.recent.attitude.length} solutions ` +
    `(at most ${limits.recent}); ${data.long.sensors.length} long-window points (at most ${limits.long})`);
  const disabled = rest.source.controls_disabled;
  for (const b of document.querySelectorAll(".controls button, .controls input")) b.disabled = disabled !== null;
  const noJob = rest.source.job === null;
  if (noJob) $("cmd-configure").disabled = true;
  setText("controls-reason", disabled !== null ? "Commands disabled: " + disabled
    : noJob ? "Configure needs a job file: start with --job JOB.json." : "Job file: " + rest.source.job);
  setText("config-version", rest.source.config_version === null ? "no reply yet" : rest.source.config_version);
  fillList("calibration", rest.source.calibration);
  if (rest.events) fillList("events", rest.events.slice().reverse());
  if (rest.commands) fillList("commands", rest.commands.map((c) => `${c.label}: ${c.result}`).reverse());
  if (rest.stations) showStations(rest.stations);
}

function fillList(id, items) {
  const el = $(id);
  el.replaceChildren(...items.map((t) => { const li = document.createElement("li"); li.textContent = t; return li; }));
}

function showStations(st) {
  setText("survey-note", st.note);
  const rows = st.rows.slice().reverse().map((s) => {
    const tr = document.createElement("tr");
    const cells = [s.number, s.time_s.toFixed(2), s.md === null ? "n/a" : s.md, s.inclination, s.azimuth, s.toolface, s.position];
    cells.forEach((c, i) => {
      const td = document.createElement("td");
      td.textContent = c;
      if (i === 4) td.className = "station-azimuth" + (String(c).startsWith("undetermined") ? " undetermined" : "");
      tr.appendChild(td);
    });
    if (s.invalid) tr.className = "invalid";
    return tr;
  });
  $("stations").replaceChildren(...rows);
  // No determined position: the note says why; no empty axes.
  $("station-charts").style.display = st.plan.length ? "" : "none";
  plot.plan.setData([null, [st.plan.map((p) => p[0]), st.plan.map((p) => p[1])]]);
  plot.section.setData([null, [st.section.map((p) => p[0]), st.section.map((p) => p[1])]]);
}

// --- charts ---------------------------------------------------------------

const colors = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"];

function width(el) { return Math.max(300, el.clientWidth - 4); }

function timeChart(id, title, unit, labels, band) {
  const el = $(id);
  const series = [{ label: "t (s)" }];
  labels.forEach((label, i) => series.push({ label, stroke: colors[i % colors.length], width: 1, points: { show: false } }));
  const opts = {
    title, width: width(el), height: 190, series,
    scales: { x: { time: false } },
    axes: [{ label: "time, s" }, { label: unit, size: 60 }],
  };
  if (band) {
    // Series 1 is the value, 2 and 3 value -/+ sigma: fill between them.
    series[2].stroke = series[3].stroke = "rgba(31,119,180,0.35)";
    opts.bands = [{ series: [3, 2], fill: "rgba(31,119,180,0.15)" }];
  }
  return new uPlot(opts, [[], ...labels.map(() => [])], el);
}

function xyChart(id, title, xLabel, yLabel, flipY) {
  const el = $(id);
  const opts = {
    title, mode: 2, width: width(el), height: 260,
    scales: { x: { time: false }, y: { dir: flipY ? -1 : 1 } },
    axes: [{ label: xLabel }, { label: yLabel, size: 60 }],
    series: [{}, { label: "stations", stroke: "#1f3b57", paths: uPlot.paths.linear(), points: { show: true, size: 6 } }],
  };
  return new uPlot(opts, [null, [[], []]], el);
}

const plot = {
  gyro: timeChart("chart-gyro", "Gyro rates", "deg/s", ["part 1 (body x)", "part 2 (body z)"]),
  accel1: timeChart("chart-accel1", "Accelerometer, part 1", "m/s^2", ["x", "y", "z"]),
  accel2: timeChart("chart-accel2", "Accelerometer, part 2", "m/s^2", ["x", "y", "z"]),
  temp: timeChart("chart-temp", "Temperatures", "degC", ["gyro 1", "accel 1", "gyro 2", "accel 2"]),
  inc: timeChart("chart-inc", "Inclination +- 1 sigma", "deg", ["inclination", "-1 sigma", "+1 sigma"], true),
  azi: timeChart("chart-azi", "Azimuth +- 1 sigma (gaps: undetermined)", "deg", ["azimuth", "-1 sigma", "+1 sigma"], true),
  tf: timeChart("chart-tf", "Toolface +- 1 sigma", "deg", ["toolface", "-1 sigma", "+1 sigma"], true),
  plan: xyChart("chart-plan", "Plan view", "east, m", "north, m", false),
  section: xyChart("chart-section", "Vertical section", "section, m", "TVD, m", true),
};

function column(rows, i) { return rows.map((r) => r[i]); }

// Value and value -/+ sigma; null where either is null.
function withBand(rows, v, s) {
  const val = column(rows, v);
  const lo = rows.map((r) => (r[v] === null || r[s] === null ? null : r[v] - r[s]));
  const hi = rows.map((r) => (r[v] === null || r[s] === null ? null : r[v] + r[s]));
  return [val, lo, hi];
}

function draw() {
  if (!dirty) return;
  dirty = false;
  const d = data[view];
  const ts = column(d.sensors, 0);
  plot.gyro.setData([ts, column(d.sensors, 1), column(d.sensors, 2)]);
  plot.accel1.setData([ts, column(d.sensors, 3), column(d.sensors, 4), column(d.sensors, 5)]);
  plot.accel2.setData([ts, column(d.sensors, 6), column(d.sensors, 7), column(d.sensors, 8)]);
  plot.temp.setData([ts, column(d.sensors, 9), column(d.sensors, 10), column(d.sensors, 11), column(d.sensors, 12)]);
  const ta = column(d.attitude, 0);
  plot.inc.setData([ta, ...withBand(d.attitude, 1, 2)]);
  plot.azi.setData([ta, ...withBand(d.attitude, 3, 4)]);
  plot.tf.setData([ta, ...withBand(d.attitude, 5, 6)]);
}

setInterval(draw, 500);
window.addEventListener("resize", () => {
  for (const [name, p] of Object.entries(plot)) p.setSize({ width: width(p.root.parentElement), height: p.height });
  dirty = true;
});
$("window").addEventListener("change", (e) => { view = e.target.value; dirty = true; draw(); });

// --- commands -------------------------------------------------------------

async function command(path) {
  setText("command-response", "sending...");
  try {
    // The token tells the server the request comes from this page.
    const r = await fetch(path, { method: "POST", headers: { "X-Probe-Token": token } });
    setText("command-response", r.ok ? "sent: the probe's reply shows below" : await r.text());
  } catch (e) {
    setText("command-response", "not sent: " + e);
  }
}
$("cmd-align").onclick = () => command("/api/align");
$("cmd-station").onclick = () => command("/api/station");
$("cmd-configure").onclick = () => command("/api/configure");
$("cmd-index").onclick = () =>
  command(`/api/index/${encodeURIComponent($("index-positions").value)}/${encodeURIComponent($("index-dwell").value)}`);

// --- the stream -----------------------------------------------------------

const stream = new EventSource("/events?token=" + encodeURIComponent(token));
stream.onopen = () => setText("connection", "connected");
stream.onerror = () => setText("connection", "reconnecting...");
stream.onmessage = (m) => {
  const update = JSON.parse(m.data);
  apply(update);
  document.body.dataset.updates = String(Number(document.body.dataset.updates || 0) + 1);
  if (update.rest.finished) {
    // Nothing more will come (the capture ended, the port closed): stop
    // the stream rather than reconnect to it.
    stream.close();
    draw();
    setText("connection", "closed: the source has ended");
    document.body.dataset.finished = "true";
  }
};
