// The Live plots view (uPlot): angle and target, speed, current, power,
// temperature and the winding's estimate of one or several servos, on the
// bus clock of each answer (the simulator's clock given --sim-control).
// Pause freezes the picture, sampling goes on; CSV exports every sample.
"use strict";
(() => {
  const {$, el, on, send, state} = UI;
  const WINDOW_S = 10, KEEP = 200000, RATE_S = 2;
  const CHARTS = [
    {title: "angle, deg", keys: [["angle", ""], ["target", " target"]]},
    {title: "speed, deg/s", keys: [["speed", ""]]},
    {title: "current, A", keys: [["current", ""]]},
    {title: "power, W", keys: [["power", ""]]},
    {title: "temperature, °C", keys: [["temperature", " case"], ["winding", " winding"]]},
  ];
  const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2"];
  let rows = [], ids = [], plots = [], paused = false, dirty = false, notes = {};

  function build() {
    plots.forEach((p) => p.destroy());
    plots = [];
    $("#charts").innerHTML = "";
    for (const c of CHARTS) {
      const series = [{label: "t, s"}];
      ids.forEach((id, n) => c.keys.forEach(([, suffix], k) => series.push({
        label: `servo ${id}${suffix}`, stroke: COLOURS[n % COLOURS.length], dash: k ? [6, 4] : undefined,
        spanGaps: true, points: {show: false}})));
      const box = el("div", {class: "chart"});
      $("#charts").append(box);
      plots.push(new uPlot({title: c.title, width: 520, height: 200, series,
        scales: {x: {time: false}}, legend: {live: false}}, [[]].concat(series.slice(1).map(() => [])), box));
    }
  }

  function draw() {
    if (!dirty || paused || !plots.length) return;
    dirty = false;
    const last = rows.length ? rows[rows.length - 1].t : 0;
    let from = rows.length;
    while (from > 0 && rows[from - 1].t >= last - WINDOW_S) from--;
    const shown = rows.slice(from).filter((r) => r.angle !== undefined);
    const xs = shown.map((r) => r.t);
    CHARTS.forEach((c, ci) => {
      const data = [xs];
      ids.forEach((id) => c.keys.forEach(([key]) =>
        data.push(shown.map((r) => (r.id === id && r[key] !== undefined ? r[key] : null)))));
      plots[ci].setData(data);
    });
  }
  setInterval(draw, 100);

  // Samples a second of each servo, over the last RATE_S seconds of its
  // own timestamps (the bus clock: the simulator's given --sim-control).
  function rates() {
    const out = {};
    for (const id of ids) {
      const mine = rows.filter((r) => r.id === id && r.angle !== undefined);
      if (mine.length < 2) { out[id] = 0; continue; }
      const end = mine[mine.length - 1].t;
      const recent = mine.filter((r) => r.t > end - RATE_S);
      const span = recent[recent.length - 1].t - recent[0].t;
      out[id] = span > 0 ? (recent.length - 1) / span : 0;
    }
    return out;
  }
  setInterval(() => {
    const r = rates();
    $("#plot-rate").textContent = Object.entries(r).map(([id, v]) => `servo ${id}: ${v.toFixed(0)}/s`).join(", ") +
      (rows.length ? ` (samples a second on the bus clock; ${rows.length} kept)` : "");
  }, 500);

  on("samples", (m) => {
    for (const r of m.rows) {
      if (r.silent) { notes[r.id] = `servo ${r.id} silent: ${r.silent}`; continue; }
      if (r.note) notes[r.id] = `servo ${r.id}: ${r.note}`;
      else if (notes[r.id] && notes[r.id].includes("silent")) delete notes[r.id];
      rows.push(r);
    }
    if (rows.length > KEEP) rows = rows.slice(rows.length - KEEP);
    $("#plot-note").textContent = Object.values(notes).join("; ");
    dirty = true;
  });

  UI.onRefused("plot", (m) => { $("#plot-note").textContent = m.text; });

  on("plotting", (m) => {
    ids = m.ids;
    rows = [];    // a new round of sampling: its clock starts at 0
    notes = {};
    build();
    dirty = true;
  });

  function csv() {
    const cols = ["t", "id", "angle", "target", "speed", "current", "power", "temperature", "winding", "voltage",
      "limiter"];
    const head = "t_s,id,angle_deg,target_deg,speed_dps,current_a,power_w,temperature_c,winding_c,voltage_v,limiter";
    const lines = rows.map((r) => cols.map((c) => (r[c] === undefined || r[c] === null ? "" : r[c])).join(","));
    return [head].concat(lines).join("\n") + "\n";
  }

  function checks() {
    const box = $("#plot-ids");
    const known = Object.keys(state.servos).map(Number).filter((i) => !state.servos[i].gone);
    box.innerHTML = "";
    known.forEach((id) => box.append(el("label", {}, el("input", {type: "checkbox", value: id,
      ...((ids.length ? ids.includes(id) : id === UI.picked()) ? {checked: ""} : {})}), ` ${id} `)));
  }

  document.addEventListener("DOMContentLoaded", () => {
    $("#plot-start").addEventListener("click", () => {
      const chosen = [...document.querySelectorAll("#plot-ids input:checked")].map((i) => Number(i.value));
      if (!chosen.length && UI.picked() !== null) chosen.push(UI.picked());
      rows = [];
      notes = {};
      send({op: "plot", ids: chosen});
    });
    $("#plot-stop").addEventListener("click", () => send({op: "plot", ids: []}));
    $("#plot-pause").addEventListener("click", (e) => {
      paused = !paused;
      e.target.textContent = paused ? "Resume" : "Pause";
      dirty = true;
    });
    $("#plot-clear").addEventListener("click", () => { rows = []; dirty = true; });
    $("#plot-csv").addEventListener("click", () => {
      const a = el("a", {href: URL.createObjectURL(new Blob([csv()], {type: "text/csv"})),
        download: "servoctl-samples.csv"});
      document.body.append(a);
      a.click();
      a.remove();
    });
  });
  on("view", (m) => { if (m.view === "plots") checks(); });
  window.servoUiPlots = {rates, csv, count: () => rows.length, paused: () => paused};
})();
