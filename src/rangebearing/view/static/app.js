// rangebearing view: the state arrives as server-sent events (/api/events), the camera as MJPEG.
// Bearings are positive to the LEFT (REP 103): a neighbour on the robot's left is drawn left of it.
"use strict";

const $ = (id) => document.getElementById(id);
const deg = (rad) => (rad * 180) / Math.PI;
let lastState = null;

// --- the bird's-eye plot ---------------------------------------------------------------------
const RANGES_M = [0.5, 1, 1.5, 2, 3, 4, 6, 10];

function plotScale(canvas, landmarks) {
  const far = Math.max(0, ...landmarks.map((lm) => lm.range_m + 2 * lm.range_sigma_m));
  const maxM = RANGES_M.find((r) => r >= far * 1.1) || RANGES_M[RANGES_M.length - 1];
  const ox = canvas.width / 2, oy = canvas.height - 28;
  return { ox, oy, maxM, pxPerM: (oy - 18) / maxM };
}

// floor (x forward, y left, metres) -> canvas pixels
function toCanvas(s, xM, yM) {
  return [s.ox - yM * s.pxPerM, s.oy - xM * s.pxPerM];
}

// canvas arc angle of a bearing: straight ahead is up, positive bearings turn left
const arcAngle = (bearing) => -Math.PI / 2 - bearing;

function drawPlot(state) {
  const canvas = $("plot"), g = canvas.getContext("2d");
  const lms = state.landmarks || [];
  const s = plotScale(canvas, lms);
  Object.assign(canvas.dataset, { originX: s.ox, originY: s.oy, pxPerM: s.pxPerM, maxRangeM: s.maxM });
  g.clearRect(0, 0, canvas.width, canvas.height);
  g.font = "11px system-ui, sans-serif";
  // range rings, labelled
  const step = s.maxM <= 1 ? 0.25 : s.maxM <= 2 ? 0.5 : 1;
  g.strokeStyle = "#2f343d"; g.fillStyle = "#7d8490"; g.lineWidth = 1;
  for (let r = step; r <= s.maxM + 1e-9; r += step) {
    g.beginPath(); g.arc(s.ox, s.oy, r * s.pxPerM, Math.PI, 2 * Math.PI); g.stroke();
    g.fillText(`${+r.toFixed(2)} m`, s.ox + 3, s.oy - r * s.pxPerM - 3);
  }
  // bearing rays every 30°, and the camera's field of view dashed
  for (let b = -90; b <= 90; b += 30) {
    const [x, y] = toCanvas(s, s.maxM * Math.cos((b * Math.PI) / 180), s.maxM * Math.sin((b * Math.PI) / 180));
    g.beginPath(); g.moveTo(s.ox, s.oy); g.lineTo(x, y); g.stroke();
    if (b !== 0) g.fillText(`${b > 0 ? "+" : ""}${b}°`, x + (b > 0 ? 2 : -26), y + (Math.abs(b) === 90 ? -4 : 10));
  }
  const half = (state.hfov_rad || 0) / 2;
  if (half > 0) {
    g.save(); g.setLineDash([4, 4]); g.strokeStyle = "#56617a";
    for (const b of [-half, half]) {
      const [x, y] = toCanvas(s, s.maxM * Math.cos(b), s.maxM * Math.sin(b));
      g.beginPath(); g.moveTo(s.ox, s.oy); g.lineTo(x, y); g.stroke();
    }
    g.restore();
  }
  g.fillStyle = "#7d8490";
  g.fillText("left", 6, s.oy + 16); g.fillText("right", canvas.width - 32, s.oy + 16);
  // the robot: a triangle pointing forward
  g.fillStyle = "#e4e6ea";
  g.beginPath(); g.moveTo(s.ox, s.oy - 10); g.lineTo(s.ox - 7, s.oy + 6); g.lineTo(s.ox + 7, s.oy + 6); g.fill();
  // each neighbour: its bearing ray, its 1-sigma uncertainty, its position and label
  for (const lm of lms) {
    const colour = lm.in_envelope ? "#4cd964" : "#9aa0aa";
    const [x, y] = toCanvas(s, lm.x_m, lm.y_m);
    g.strokeStyle = colour; g.globalAlpha = 0.5;
    g.beginPath(); g.moveTo(s.ox, s.oy); g.lineTo(x, y); g.stroke();
    g.globalAlpha = 1;
    if (lm.range_sigma_m > 0 || lm.bearing_sigma_rad > 0) {
      const r0 = Math.max(0, lm.range_m - lm.range_sigma_m) * s.pxPerM;
      const r1 = (lm.range_m + lm.range_sigma_m) * s.pxPerM;
      const a0 = arcAngle(lm.bearing_rad + lm.bearing_sigma_rad), a1 = arcAngle(lm.bearing_rad - lm.bearing_sigma_rad);
      g.fillStyle = "rgba(76, 217, 100, 0.28)"; g.strokeStyle = colour;
      g.beginPath(); g.arc(s.ox, s.oy, r1, a0, a1); g.arc(s.ox, s.oy, r0, a1, a0, true); g.closePath();
      g.fill(); g.stroke();
    }
    g.fillStyle = colour;
    g.beginPath(); g.arc(x, y, 4, 0, 2 * Math.PI); g.fill();
    const tag = lm.track_id >= 0 ? `#${lm.track_id} ` : "";
    g.fillText(`${tag}${lm.range_m.toFixed(2)} m ${deg(lm.bearing_rad).toFixed(1)}°`, x + 7, y - 6);
  }
  return s;
}

// --- the readings table (its rows also say where each neighbour was plotted) -------------------
function fillTable(state, s) {
  const body = $("readings").tBodies[0];
  body.replaceChildren();
  for (const lm of state.landmarks || []) {
    const [x, y] = toCanvas(s, lm.x_m, lm.y_m);
    const tr = body.insertRow();
    tr.className = lm.in_envelope ? "lm" : "lm out";
    Object.assign(tr.dataset, {
      rangeM: lm.range_m, bearingRad: lm.bearing_rad, trackId: lm.track_id, xPx: x, yPx: y, frame: state.frame.name,
    });
    const sig = (v, f) => (v > 0 ? f(v) : "–");
    for (const text of [
      lm.track_id >= 0 ? `#${lm.track_id}` : "–",
      `${lm.range_m.toFixed(3)} m`,
      `${deg(lm.bearing_rad) >= 0 ? "+" : ""}${deg(lm.bearing_rad).toFixed(2)}°`,
      sig(lm.range_sigma_m, (v) => `${(v * 1000).toFixed(1)} mm`),
      sig(lm.bearing_sigma_rad, (v) => `${deg(v).toFixed(2)}°`),
      `${Math.round(lm.visible * 100)} %`,
      lm.range_rate_mps === null ? "–" : `${lm.range_rate_mps >= 0 ? "+" : ""}${(lm.range_rate_mps * 1000).toFixed(0)} mm/s`,
    ]) tr.insertCell().textContent = text;
  }
}

// --- loop figures ------------------------------------------------------------------------------
function showFigures(state) {
  const st = state.stats || {}, v = state.view || {};
  const rows = [
    ["frame", `${state.frame.name} (${state.frame.width}×${state.frame.height}${state.frame.tracked ? ", tracked" : ""})`],
    ["fps", (st.fps ?? 0).toFixed(1)],
    ["frames", st.frames ?? "–"],
    ["dropped", st.dropped ?? "–"],
    ["bad frames", st.bad_frames ?? "–"],
    ["latency", st.latency_ms_p50 === undefined ? "–"
      : `p50 ${st.latency_ms_p50.toFixed(2)} ms, p99 ${st.latency_ms_p99.toFixed(2)} ms`],
  ];
  for (const [k, ms] of Object.entries(st.stage_ms || {})) rows.push([`${k}`, `${ms.toFixed(2)} ms`]);
  rows.push(["view encode", `${(v.encode_ms ?? 0).toFixed(1)} ms (≤ ${v.max_fps} fps, ${v.viewers} viewers)`]);
  const dl = $("figures");
  dl.replaceChildren();
  for (const [k, val] of rows) {
    const dt = document.createElement("dt"), dd = document.createElement("dd");
    dt.textContent = k; dd.textContent = val; dd.dataset.key = k;
    dl.append(dt, dd);
  }
  const status = $("status");
  status.textContent = `live · ${(st.fps ?? 0).toFixed(1)} fps · ${(state.landmarks || []).length} in view`;
  status.className = "status live";
}

function update(state) {
  lastState = state;
  document.body.dataset.seq = state.seq;
  document.body.dataset.sMin = state.thresholds.s_min;
  const s = drawPlot(state);
  fillTable(state, s);
  showFigures(state);
}

// --- threshold controls --------------------------------------------------------------------------
function slider(form, id, label, value, max) {
  const row = document.createElement("div");
  row.className = "row";
  row.innerHTML = `<label for="${id}">${label}</label><input type="range" id="${id}" min="0" max="${max}" step="1">` +
    `<output for="${id}"></output>`;
  form.append(row);
  const input = row.querySelector("input"), out = row.querySelector("output");
  input.value = value; out.textContent = value;
  input.addEventListener("input", () => { out.textContent = input.value; scheduleSend(); });
}

function buildControls(t) {
  const form = $("thresholds");
  form.replaceChildren();
  for (const key of ["red_hue", "blue_hue"]) {
    const fs = document.createElement("fieldset");
    fs.dataset.key = key;
    fs.innerHTML = `<legend>${key === "red_hue" ? "red" : "blue"} hue</legend>`;
    t[key].forEach(([lo, hi], i) => {
      slider(fs, `${key}-${i}-lo`, `range ${i + 1} low`, lo, 179);
      slider(fs, `${key}-${i}-hi`, `range ${i + 1} high`, hi, 179);
    });
    form.append(fs);
  }
  slider(form, "s_min", "saturation ≥", t.s_min, 255);
  slider(form, "v_min", "value ≥", t.v_min, 255);
}

function readControls() {
  const out = {};
  for (const fs of $("thresholds").querySelectorAll("fieldset")) {
    const n = fs.querySelectorAll("input").length / 2;
    out[fs.dataset.key] = Array.from({ length: n }, (_, i) => [
      +$(`${fs.dataset.key}-${i}-lo`).value, +$(`${fs.dataset.key}-${i}-hi`).value,
    ]);
  }
  out.s_min = +$("s_min").value;
  out.v_min = +$("v_min").value;
  return out;
}

function say(text, ok) {
  const m = $("message");
  m.textContent = text;
  m.className = ok ? "ok" : "error";
}

async function post(url, body) {
  const r = await fetch(url, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });
  const data = await r.json().catch(() => ({ error: `HTTP ${r.status}` }));
  if (!r.ok) throw new Error(data.error || `HTTP ${r.status}`);
  return data;
}

let sendTimer = null;
function scheduleSend() {
  clearTimeout(sendTimer);
  sendTimer = setTimeout(async () => {
    try {
      const data = await post("/api/thresholds", readControls());
      say(`detecting with s ≥ ${data.thresholds.s_min}, v ≥ ${data.thresholds.v_min} (not saved)`, true);
    } catch (e) { say(e.message, false); }
  }, 120);
}

async function save() {
  try {
    const data = await post("/api/save", {});
    say(`saved to ${data.saved} (the old file is ${data.backup})`, true);
  } catch (e) { say(e.message, false); }
}

// --- start -------------------------------------------------------------------------------------------
async function start() {
  const r = await fetch("/api/thresholds");
  const t = await r.json();
  buildControls(t.thresholds);
  $("save").disabled = !t.config_file;
  $("config-file").textContent = t.config_file ? t.config_file : "(started without --config: nothing to save to)";
  $("save").addEventListener("click", save);
  $("show-masks").addEventListener("change", (e) => {
    const img = $("masks");
    img.hidden = !e.target.checked;
    if (e.target.checked) img.src = "/stream.mjpg?layer=masks"; else img.removeAttribute("src");
  });
  const events = new EventSource("/api/events");
  let wasDown = false;
  events.onmessage = (e) => update(JSON.parse(e.data));
  events.onerror = () => {
    wasDown = true;
    $("status").textContent = "disconnected, retrying…"; $("status").className = "status down";
  };
  events.onopen = () => {  // the server came back (a restarted daemon): reopen the streams too
    if (!wasDown) return;
    wasDown = false;
    for (const img of [$("stream"), $("masks")]) {
      const src = img.getAttribute("src");
      if (src) { img.removeAttribute("src"); setTimeout(() => { img.src = src; }, 0); }
    }
  };
}

start().catch((e) => say(`cannot start: ${e.message}`, false));
