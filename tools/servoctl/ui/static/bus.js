// The Bus view: scan (one or every baud rate), the live table of servos
// (servoctl info each second), shared IDs resolved by serial, bring-up.
"use strict";
(() => {
  const {$, el, on, send, run, state, log} = UI;
  let found = [];   // servoctl scan --json
  let rows = {};    // id: servoctl info --json, or {gone, why}
  let shown = [];   // found[i]: its row's cells, made once a scan

  const hex = (n, w) => "0x" + Number(n).toString(16).padStart(w, "0");

  // The rows, made once a scan. The live table's redraws (each second) only
  // change their text: a row taken out of the page and put back would lose
  // the focus of a field the user types in, and a click whose press and
  // release straddle it (the browser drops a click whose button left the
  // page in between), so a shared ID's "assign" did nothing.
  function build() {
    const body = $("#bus-table tbody");
    body.innerHTML = "";
    shown = found.map((f) => {
      const serials = el("td");
      if (f.shared) {
        f.serials.forEach((s) => serials.append(assignControl(s)));
        if (!f.serials.length) {
          serials.append(el("div", {class: "note", text: "their answers collide, so no serial number came " +
            "through: type one (its label), or connect them one at a time and scan"}));
        }
        serials.append(assignControl(null));
      } else {
        serials.textContent = f.serials.map((s) => hex(s, 8)).join(", ");
      }
      const cells = [0, 1, 2, 3, 4, 5, 6].map(() => el("td"));
      cells[6].className = "state";
      const tr = el("tr", {"data-id": f.id}, el("td", {text: f.id}), serials, ...cells);
      body.append(tr);
      return {tr, cells};
    });
    render();
  }

  function render() {
    found.forEach((f, i) => {
      const {tr, cells} = shown[i];
      const info = f.shared ? undefined : rows[f.id];
      const cls = f.shared ? "shared" : info && info.gone ? "gone" : "";
      if (tr.className !== cls) tr.className = cls;
      const ok = info && !info.gone;
      [ok ? hex(info.model, 4) : "", ok ? hex(info.firmware, 4) : "", ok ? info.voltage_v.toFixed(2) : "",
        ok && info.temperature_c !== null ? info.temperature_c.toFixed(1) : "",
        ok ? (info.status.join(", ") || "ok") : "", ok ? (info.limiter || "—") : "", stateText(f, info),
      ].forEach((text, c) => { if (cells[c].textContent !== text) cells[c].textContent = text; });
    });
  }

  function stateText(f, info) {
    if (f.mode === "bootloader") return "in its bootloader: update installs an application";
    if (f.shared) return `ID ${f.id} shared: give each a free ID by its serial`;
    if (info && info.gone) return `gone: ${info.why}`;
    if (info && info.winding_c === undefined) return "answering (maker's firmware)";
    return info ? "answering" : "";
  }

  // servoctl id assign SERIAL ID: a serial heard, or (serial null) one typed.
  function assignControl(serial) {
    const input = el("input", {type: "number", min: 0, max: 253, value: nextFree(), size: 4, class: "new-id"});
    const typed = serial === null ? el("input", {size: 11, placeholder: "0x51a00000", class: "serial"}) : null;
    const said = el("span", {class: "note"});
    const b = el("button", {text: "assign", onclick: async () => {
      const r = await run(["id", "assign", typed ? typed.value : hex(serial, 8), input.value]);
      said.textContent = r.code ? r.err : r.out;
      said.className = r.code ? "refused" : "done";
      if (!r.code) scan(false);
    }});
    return el("div", {}, typed || hex(serial, 8), " → ID ", input, b, said);
  }

  function nextFree() {
    const used = new Set(found.map((f) => f.id));
    for (let i = 1; i < 254; i++) if (!used.has(i)) return i;
    return 253;
  }

  function scan(allBauds) {
    const line = $("#scan-line");
    line.className = "note";
    line.textContent = allBauds ? "scanning every baud rate…" : "scanning…";
    if (!send({op: "scan", all_bauds: allBauds})) line.textContent = "not scanned: not connected";
  }

  // A scan refused (a full queue, a watching tab) or dropped by STOP ALL: said on its line.
  UI.onRefused("scan", (m) => {
    $("#scan-line").textContent = m.text;
    $("#scan-line").className = "note refused";
  });

  on("scan", (m) => {
    found = m.found;
    rows = {};
    const n = found.length;
    const lines = (m.err || "").split("\n").filter((l) => l);
    // Interrupted (STOP ALL): only the part of the bus it reached is listed.
    const part = m.code === 130 ? "scan interrupted, the list is partial (scan again for the whole bus); " : "";
    $("#scan-line").className = m.code === 130 ? "note refused" : "note";
    $("#scan-line").textContent = part + (n ? `${n} ID(s) answered` + (lines.length ? `; ${lines.join("; ")}` : "")
      : "no servo answered" + (lines.length ? `: ${lines.join("; ")}` : ""));
    UI.setServos(found.filter((f) => f.mode === "application" && !f.shared).map((f) => f.id));
    build();
  });

  on("table", (m) => {
    for (const r of m.rows) {
      rows[r.id] = r;
      state.servos[r.id] = {info: r.gone ? (state.servos[r.id] || {}).info : r, gone: !!r.gone, why: r.why};
    }
    render();
    UI.greyOwn();
  });

  document.addEventListener("DOMContentLoaded", () => {
    $("#scan").addEventListener("click", () => scan(false));
    $("#scan-all").addEventListener("click", () => scan(true));
    $("#bu-go").addEventListener("click", async () => {
      const argv = ["id", "bringup", "--from-id", $("#bu-from").value, "--first", $("#bu-first").value,
        "--count", $("#bu-count").value, "--wait-s", $("#bu-wait").value];
      // Its own line: the scan after it rewrites the scan's line, and the reason stays.
      const said = $("#bu-said");
      said.className = "note";
      said.textContent = "bring-up: connect the new servos one after another…";
      const r = await run(argv, (l) => { said.textContent = l.text; });
      said.textContent = (r.code ? r.err : r.out).trim().split("\n").pop();
      said.className = r.code ? "refused" : "done";
      scan(false);
    });
  });
  UI.on("hello", (m) => { if (m.role === "driver" && !found.length) scan(false); });
})();
