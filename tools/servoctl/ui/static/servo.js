// The Servo view: every data item in units with its range and factory value
// (from servoctl's schema), edited in place with servoctl config set; config
// files saved, loaded and diffed; the bus backed up and restored.
"use strict";
(() => {
  const {$, el, on, send, run, runInto, picked} = UI;

  let shown = null;  // whose items the table shows, or is about to

  function read() {
    const id = picked();
    shown = id;
    if (id === null) { said("servoctl ui: no servo picked: scan found none"); return; }
    $("#items tbody").innerHTML = "";
    send({op: "items", id});
  }

  // Said in the items' table: a servo that does not answer (once), or a
  // read refused by a full queue or dropped by STOP ALL.
  function said(text) {
    const body = $("#items tbody");
    body.innerHTML = "";
    body.append(el("tr", {class: "said"}, el("td", {colspan: 7, class: "why refused", text})));
  }

  on("items", (m) => {
    if (m.id !== picked()) return;
    if (m.silent) { said(m.silent); return; }
    const body = $("#items tbody");
    body.innerHTML = "";
    for (const it of m.items) body.append(row(m.id, it));
  });
  UI.onRefused("items", (m) => said(m.text));

  function row(id, it) {
    const why = el("td", {class: "why"});
    let value;
    if (it.missing) {
      value = el("span", {class: "missing", text: "—"});
      why.textContent = it.missing;
      why.className = "why missing";
    } else if (it.writable) {
      value = el("input", {value: it.edit, name: it.name, title: it.value,
        list: it.names.length ? `names-${it.name}` : ""});
      if (it.names.length) {
        const dl = el("datalist", {id: `names-${it.name}`});
        it.names.forEach((n) => dl.append(el("option", {value: n})));
        why.append(dl);
      }
      value.addEventListener("keydown", async (e) => {
        if (e.key !== "Enter") return;
        const r = await run(["config", "set", id, it.name, value.value]);
        why.textContent = r.code ? r.err.trim() : r.out.trim();
        why.className = "why " + (r.code ? "refused" : "done");
        if (!r.code) { value.title = r.out.trim(); }
      });
    } else {
      value = el("span", {text: it.value});
    }
    const kept = el("td");
    kept.append(el("span", {class: it.ram ? "badge ram" : "badge", text: it.area}));
    if (it.m0) why.append(el("div", {class: "note", text: it.m0}));
    const name = el("td", {text: it.name, title: it.help});
    return el("tr", {"data-item": it.name}, el("td", {text: it.id}), name, el("td", {}, value),
      el("td", {text: it.range}), el("td", {text: it.factory}), kept, why);
  }

  document.addEventListener("DOMContentLoaded", () => {
    const out = $("#servo-out");
    $("#items-read").addEventListener("click", read);
    $("#cfg-save").addEventListener("click", () => runInto(out, ["config", "save", picked(), $("#cfg-file").value]));
    $("#cfg-load").addEventListener("click", async () => {
      await runInto(out, ["config", "load", picked(), $("#cfg-file").value]);
      read();
    });
    $("#cfg-diff").addEventListener("click", async () => {
      const r = await runInto(out, ["config", "diff", picked(), $("#cfg-other").value || "factory"]);
      if (r.code === 1) out.classList.remove("refused");  // exit 1: they differ, as listed
    });
    $("#bk-save").addEventListener("click", () => {
      const ids = Object.keys(UI.state.servos).filter((i) => !UI.state.servos[i].gone);
      runInto(out, ["backup", $("#bk-file").value].concat(ids.length ? ["--ids", ...ids] : []));
    });
    $("#bk-restore").addEventListener("click", () => runInto(out, ["restore", $("#bk-file").value]));
  });
  // A scan that keeps the picked servo (a late one, or after a bring-up) leaves
  // its table, and what a user is typing there, as it is.
  on("picked", (m) => { if (!$("#view-servo").hidden && m.id !== shown) read(); });
  on("view", (m) => {
    if (m.view === "servo" && (!$("#items tbody").children.length || shown !== picked())) read();
  });
})();
