// servoctl ui: the page's core. One WebSocket to servoctl; every action is a
// servoctl command the server runs with servoctl's own library, so what the
// page says when a value is refused is what servoctl says.
"use strict";
const UI = (() => {
  const token = document.body.dataset.token;
  const handlers = {};        // message type: [fn]
  const waiting = {};         // tag: {resolve, onLine}
  let ws = null, tag = 0, role = "connecting";
  const state = {servos: {}, picked: null, about: {}, stepping: false};

  const $ = (sel) => document.querySelector(sel);
  const el = (tagName, attrs = {}, ...kids) => {
    const e = document.createElement(tagName);
    for (const [k, v] of Object.entries(attrs)) {
      if (k === "class") e.className = v; else if (k === "text") e.textContent = v;
      else if (k.startsWith("on")) e.addEventListener(k.slice(2), v); else e.setAttribute(k, v);
    }
    for (const k of kids) e.append(k);
    return e;
  };
  const on = (type, fn) => (handlers[type] = handlers[type] || []).push(fn);

  function log(text, cls) {
    const l = $("#log");
    const line = el("div", {text, class: cls || ""});
    l.append(line);
    while (l.childNodes.length > 200) l.firstChild.remove();
    l.scrollTop = l.scrollHeight;
  }

  function connect() {
    const proto = location.protocol === "https:" ? "wss:" : "ws:";
    ws = new WebSocket(`${proto}//${location.host}/ws?token=${encodeURIComponent(token)}`);
    ws.onmessage = (ev) => handle(JSON.parse(ev.data));
    ws.onopen = tellStopMode;
    ws.onclose = () => { setRole("closed", "the server has stopped (servoctl ui ended)"); };
  }

  function handle(msg) {
    if (msg.type === "line" && waiting[msg.tag] && waiting[msg.tag].onLine) waiting[msg.tag].onLine(msg);
    // Refused before it ran (a full queue, a watching tab): the request that asked hears it.
    if ((msg.type === "error" || msg.type === "busy") && msg.tag != null && waiting[msg.tag]) {
      waiting[msg.tag].resolve({code: 2, out: "", err: msg.text});
      delete waiting[msg.tag];
    }
    if ((msg.type === "error" || msg.type === "busy") && msg.op) {  // a scan, items or a plot refused or dropped
      (handlers[`refused-${msg.op}`] || []).forEach((fn) => fn(msg));
    }
    if (msg.type === "result") {
      log(`$ ${msg.command}  -> exit ${msg.code}`, msg.code ? "refused" : "");
      if (waiting[msg.tag]) { waiting[msg.tag].resolve(msg); delete waiting[msg.tag]; }
    }
    (handlers[msg.type] || []).forEach((fn) => fn(msg));
  }

  // What the server stops every servo with should this tab close while it
  // drives: STOP ALL's mode, as chosen here.
  function tellStopMode() { send({op: "stopmode", mode: $("#stop-mode").value}); }

  function send(obj) {
    if (!ws || ws.readyState !== 1) return false;
    ws.send(JSON.stringify(obj));
    return true;
  }

  // Runs one servoctl command line (without "servoctl" and the bus options):
  // resolves with {code, out, err}; onLine hears each line as it is printed.
  // req: a request of another op answered as a command is (a jog), argv
  // then only what it runs.
  function run(argv, onLine, req) {
    const t = ++tag;
    if (argv.some((a) => a === null || a === undefined)) {  // the servo picker is empty
      return Promise.resolve({code: 2, out: "", err: "servoctl ui: no servo picked: scan found none"});
    }
    return new Promise((resolve) => {
      waiting[t] = {resolve, onLine};
      if (!send(req ? Object.assign({}, req, {tag: t}) : {op: "run", argv: argv.map(String), tag: t})) {
        delete waiting[t];
        resolve({code: -1, out: "", err: "not connected"});
      }
    });
  }

  // A command's output into a <pre>: its lines as they come, the error red.
  // An answer that came with no line (refused by a full queue, dropped by
  // STOP ALL, a watching tab's) is shown here too, not only in the log.
  async function runInto(pre, argv, req) {
    pre.textContent = `$ servoctl ${argv.join(" ")}\n`;
    let heard = 0;
    const r = await run(argv, (m) => {
      heard++;
      pre.textContent += m.text + "\n";
      pre.scrollTop = pre.scrollHeight;
    }, req);
    pre.classList.toggle("refused", r.code !== 0);
    const said = heard ? "" : [r.out, r.err].filter((t) => t).join("\n").trim();
    if (said) pre.textContent += said + "\n";
    else if (!r.out && !r.err) pre.textContent += r.code ? `exit ${r.code}\n` : "done\n";
    return r;
  }

  function setRole(r, holder) {
    role = r;
    const badge = $("#role");
    badge.className = "role " + r;
    badge.textContent = r === "driver" ? "this tab drives the bus" :
      r === "viewer" ? `watching: ${holder}` : holder || r;
    document.body.classList.toggle("viewer", r !== "driver");
    $("main").inert = r !== "driver";  // neither click nor keyboard reaches a watching tab's controls
    $("#stop-all").disabled = r === "closed";  // a watching tab may stop every servo too
  }

  on("hello", (m) => {
    state.about = m;
    $("#bus-port").textContent = `${m.port}${m.simulator ? " (simulator)" : ""}`;
    setRole(m.role, m.holder ? `${m.holder} drives the bus` : "");
  });
  on("busy", (m) => { setRole("viewer", `${m.holder} drives the bus`); log(m.text, "refused"); });
  on("error", (m) => log(m.text, "refused"));
  // Counted by their answers: a servo silent at the host's rate is not said to be stopped.
  on("stopped", (m) => log(`stop-all: ${(m.answered || m.ids).length} of ${m.ids.length} servo(s) ` +
      `${m.mode === "damping" ? "damped" : "released"}, by their answers` +
      (m.failed.length ? `; ${m.failed.join("; ")}` : ""), m.failed.length ? "refused" : "done"));

  // The servo the Servo, Motion and Bring-up views act on.
  function picked() { return state.picked; }
  function setServos(ids) {
    const sel = $("#servo-pick");
    const keep = state.picked;
    sel.innerHTML = "";
    if (!ids.length) sel.append(el("option", {value: "", text: "(none found)"}));
    for (const id of ids) sel.append(el("option", {value: id, text: `ID ${id}`}));
    state.picked = ids.includes(keep) ? keep : (ids.length ? ids[0] : null);
    if (state.picked !== null) sel.value = state.picked;
    (handlers["picked"] || []).forEach((fn) => fn({id: state.picked}));
  }
  function whyNot(id) {
    // What this firmware's own features need: a servo that answers none of
    // items 64-67 (the maker's firmware) has none of them.
    const s = state.servos[id];
    return s && s.info && s.info.winding_c === undefined
      ? `servo ${id} answers none of items 64-67 (the maker's firmware): this firmware's feature` : "";
  }
  function greyOwn() {
    const why = state.picked === null ? "" : whyNot(state.picked);
    document.querySelectorAll("[data-needs=own]").forEach((f) => {
      f.classList.toggle("off", !!why);
      f.dataset.why = why;
      // A Bring-up step that runs keeps them off until it ends (bringup.js).
      f.querySelectorAll("button,input,select").forEach((b) => { b.disabled = !!why || state.stepping; });
    });
  }

  document.addEventListener("DOMContentLoaded", () => {
    $("#servo-pick").addEventListener("change", (e) => {
      state.picked = e.target.value === "" ? null : Number(e.target.value);
      (handlers["picked"] || []).forEach((fn) => fn({id: state.picked}));
    });
    on("picked", greyOwn);
    document.querySelectorAll("#tabs button").forEach((b) => b.addEventListener("click", () => show(b.dataset.view)));
    $("#stop-mode").addEventListener("change", tellStopMode);
    $("#stop-all").addEventListener("click", () => {
      send({op: "stopall", mode: $("#stop-mode").value});
    });
    connect();
  });

  function show(view) {
    document.querySelectorAll("#tabs button").forEach((b) => b.classList.toggle("on", b.dataset.view === view));
    document.querySelectorAll(".view").forEach((v) => { v.hidden = v.id !== `view-${view}`; });
    (handlers["view"] || []).forEach((fn) => fn({view}));
  }

  const onRefused = (op, fn) => on(`refused-${op}`, fn);

  return {$, el, on, onRefused, handle, send, run, runInto, log, state, picked, setServos, whyNot, greyOwn, show,
          role: () => role};
})();
