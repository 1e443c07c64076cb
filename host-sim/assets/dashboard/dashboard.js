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
  // Nothing to draw (no position, no plan): the note says why; no empty axes.
  const wellPlan = st.well_plan;
  $("station-charts").style.display = st.plan.length || wellPlan ? "" : "none";
  setText("ellipse-sigma", st.ellipse_sigma);
  setText("plan-title", "Plan view (north up)");
  setText("section-title", `Vertical section along ${st.section_azimuth_deg.toFixed(1)} deg (TVD down)`);
  drawWell($("plan-view"), {
    stations: st.plan, ellipses: st.plan_ellipses, plan: wellPlan ? wellPlan.plan : [],
    xLabel: "east, m", yLabel: "north, m", equal: true, yDown: false,
  });
  drawWell($("section-view"), {
    stations: st.section, ellipses: st.section_ellipses, plan: wellPlan ? wellPlan.section : [],
    xLabel: "vertical section, m", yLabel: "TVD, m", equal: false, yDown: true,
  });
}

// --- the well in plan and section (SVG) -------------------------------------

const SVG_NS = "http://www.w3.org/2000/svg";

function svgEl(name, attrs, text) {
  const el = document.createElementNS(SVG_NS, name);
  for (const [k, v] of Object.entries(attrs)) el.setAttribute(k, String(v));
  if (text !== undefined) el.textContent = text;
  return el;
}

// About `count` round-numbered ticks over [lo, hi], as [value, text].
function ticks(lo, hi, count) {
  const raw = (hi - lo) / count;
  const mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => s >= raw) || raw;
  const decimals = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
  const out = [];
  for (let k = Math.ceil(lo / step); k * step <= hi + step * 1e-9; k++) out.push([k * step, (k * step).toFixed(decimals)]);
  return out;
}

// [lo, hi] of the values, widened by 5 % (and to at least 1 m).
function range(values) {
  let lo = Math.min(...values), hi = Math.max(...values);
  const pad = Math.max((hi - lo) * 0.05, 0.5 - (hi - lo) / 2, 0);
  return [lo - pad, hi + pad];
}

// Stations (points joined in order), their ellipses ([x, y, semi-major,
// semi-minor, angle from +x towards +y in deg]) and the plan, in data
// coordinates (m). `equal`: one scale on both axes (true shape); else the
// vertical may be stretched to fill the box (the axis says by how much).
// `yDown`:
// y grows downwards (TVD).
function drawWell(svg, v) {
  const [W, H] = [560, 360];
  const m = { left: 64, right: 12, top: 10, bottom: 40 };
  const [pw, ph] = [W - m.left - m.right, H - m.top - m.bottom];
  const xs = [], ys = [];
  for (const [x, y] of v.stations.concat(v.plan)) { xs.push(x); ys.push(y); }
  for (const [x, y, a] of v.ellipses) { xs.push(x - a, x + a); ys.push(y - a, y + a); }
  if (!xs.length) { svg.replaceChildren(); return; }
  let [x0, x1] = range(xs), [y0, y1] = range(ys);
  let sx = pw / (x1 - x0), sy = ph / (y1 - y0);
  // Equal scales, or (a section) the vertical stretched to fill the box,
  // never squashed.
  if (v.equal || sy <= sx) {
    const s = Math.min(sx, sy);
    const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    [x0, x1] = [cx - pw / s / 2, cx + pw / s / 2];
    [y0, y1] = [cy - ph / s / 2, cy + ph / s / 2];
    sx = sy = s;
  }
  const X = (x) => m.left + (x - x0) * sx;
  const Y = (y) => (v.yDown ? m.top + (y - y0) * sy : m.top + ph - (y - y0) * sy);
  const parts = [];
  for (const [t, text] of ticks(x0, x1, 6)) {
    parts.push(svgEl("line", { class: "grid", x1: X(t), x2: X(t), y1: m.top, y2: m.top + ph }));
    parts.push(svgEl("text", { x: X(t), y: m.top + ph + 14, "text-anchor": "middle" }, text));
  }
  for (const [t, text] of ticks(y0, y1, 5)) {
    parts.push(svgEl("line", { class: "grid", x1: m.left, x2: m.left + pw, y1: Y(t), y2: Y(t) }));
    parts.push(svgEl("text", { x: m.left - 4, y: Y(t) + 4, "text-anchor": "end" }, text));
  }
  parts.push(svgEl("rect", { class: "axis", x: m.left, y: m.top, width: pw, height: ph }));
  const exaggeration = sy > sx * 1.001 ? ` (vertical exaggeration ${(sy / sx).toFixed(1)}x)` : "";
  parts.push(svgEl("text", { x: m.left + pw / 2, y: H - 6, "text-anchor": "middle" }, v.xLabel));
  parts.push(svgEl("text", { x: 12, y: m.top + ph / 2, "text-anchor": "middle",
    transform: `rotate(-90 12 ${m.top + ph / 2})` }, v.yLabel + exaggeration));
  const clip = `clip-${svg.id}`;
  const defs = svgEl("defs", {});
  const clipPath = svgEl("clipPath", { id: clip });
  clipPath.appendChild(svgEl("rect", { x: m.left, y: m.top, width: pw, height: ph }));
  defs.appendChild(clipPath);
  parts.unshift(defs);
  const inside = svgEl("g", { "clip-path": `url(#${clip})` });
  const line = (points) => points.map(([x, y]) => `${X(x).toFixed(1)},${Y(y).toFixed(1)}`).join(" ");
  if (v.plan.length) inside.appendChild(svgEl("polyline", { class: "well-plan", points: line(v.plan) }));
  for (const [x, y, a, b, deg] of v.ellipses) {
    // Rotated in data axes, then scaled (flipped when y is up) onto the box.
    const g = svgEl("g", { transform: `translate(${X(x)} ${Y(y)}) scale(${sx} ${v.yDown ? sy : -sy}) rotate(${deg})` });
    g.appendChild(svgEl("ellipse", { class: "ellipse", rx: a, ry: b, "vector-effect": "non-scaling-stroke" }));
    inside.appendChild(g);
  }
  if (v.stations.length) inside.appendChild(svgEl("polyline", { class: "stations", points: line(v.stations) }));
  for (const [x, y] of v.stations) inside.appendChild(svgEl("circle", { class: "station", cx: X(x), cy: Y(y), r: 3 }));
  parts.push(inside);
  svg.replaceChildren(...parts);
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

const plot = {
  gyro: timeChart("chart-gyro", "Gyro rates", "deg/s", ["part 1 (body x)", "part 2 (body z)"]),
  accel1: timeChart("chart-accel1", "Accelerometer, part 1", "m/s^2", ["x", "y", "z"]),
  accel2: timeChart("chart-accel2", "Accelerometer, part 2", "m/s^2", ["x", "y", "z"]),
  temp: timeChart("chart-temp", "Temperatures", "degC", ["gyro 1", "accel 1", "gyro 2", "accel 2"]),
  inc: timeChart("chart-inc", "Inclination +- 1 sigma", "deg", ["inclination", "-1 sigma", "+1 sigma"], true),
  azi: timeChart("chart-azi", "Azimuth +- 1 sigma (gaps: undetermined)", "deg", ["azimuth", "-1 sigma", "+1 sigma"], true),
  tf: timeChart("chart-tf", "Toolface +- 1 sigma", "deg", ["toolface", "-1 sigma", "+1 sigma"], true),
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
  const azi = unwrapAngle([ta, ...withBand(d.attitude, 3, 4)]);
  const tf = unwrapAngle([ta, ...withBand(d.attitude, 5, 6)]);
  plot.azi.setData(azi.series);
  plot.tf.setData(tf.series);
  // For the browser test: the wraps crossed and the largest step drawn.
  document.body.dataset.toolfaceWraps = String(tf.wraps);
  document.body.dataset.toolfaceMaxStep = String(tf.maxStep);
}

// An angle in [0, 360) that goes from 359 to 1 deg has turned 2 deg, not
// 358: the curve goes on continuously through the wrap (to -1 or 361 deg,
// the same direction), and is broken (a point with no value between) only
// where going on would take it beyond -180 or 540 deg (a string turning
// round and round), so that it stays readable. `series`: [t, value, lo,
// hi]. Also returns how many wraps were crossed and the largest step left
// joined.
function unwrapAngle(series) {
  const [t, val, lo, hi] = series;
  const out = [[], [], [], []];
  let prev = null, wraps = 0, maxStep = 0;
  for (let i = 0; i < t.length; i++) {
    let shift = 0;
    const v = val[i];
    if (v !== null && prev !== null) {
      shift = 360 * Math.round((prev.v - v) / 360);
      if (Math.abs(v - prev.raw) > 180) wraps++;
      if (v + shift < -180 || v + shift > 540) {
        out[0].push((prev.t + t[i]) / 2);
        out[1].push(null); out[2].push(null); out[3].push(null);
        shift = 0;
      } else if (prev.i === i - 1) {
        maxStep = Math.max(maxStep, Math.abs(v + shift - prev.v));
      }
    }
    const moved = (x) => (x === null ? null : x + shift);
    out[0].push(t[i]); out[1].push(moved(v)); out[2].push(moved(lo[i])); out[3].push(moved(hi[i]));
    if (v !== null) prev = { t: t[i], v: v + shift, raw: v, i };
  }
  return { series: out, wraps, maxStep };
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
