// The Bring-up view: calibrate, identify and tune as steps with their
// progress and figures (servoctl's own lines as they are printed), the
// fault history with clear, the bus watchdog, firmware updates of several
// servos in a row (with a bootloader caught at power-up for recovery).
"use strict";
(() => {
  const {$, runInto, picked} = UI;

  async function step(argv) {
    const prog = $("#br-prog");
    prog.removeAttribute("value");  // no figure yet: indeterminate
    prog.hidden = false;
    // Off until the step ends: the live table's greyOwn() (each second) keeps them so.
    UI.state.stepping = true;
    document.querySelectorAll("#view-bringup button").forEach((b) => { b.disabled = true; });
    try {
      return await runInto($("#bringup-out"), argv);
    } finally {
      prog.hidden = true;
      UI.state.stepping = false;
      document.querySelectorAll("#view-bringup button").forEach((b) => { b.disabled = false; });
      UI.greyOwn();  // what this servo's firmware lacks stays off
    }
  }

  UI.on("line", (m) => {  // identify's and tune's "  step 3/8"
    const at = /^\s*step (\d+)\/(\d+)/.exec(m.text);
    if (at) { $("#br-prog").max = Number(at[2]); $("#br-prog").value = Number(at[1]); }
  });
  UI.on("progress", (m) => {  // an update's bytes, a tenth at a time
    const prog = $("#br-prog");
    prog.max = m.total;
    prog.value = m.done;
    prog.title = m.text;
    $("#up-at").textContent = m.text;
  });

  function showWatchdog() {  // servoctl info's "100 ms, then hold", or "off"
    const s = UI.state.servos[picked()];
    const w = s && s.info && s.info.watchdog;
    if (!w) return;
    const at = /^(\d+) ms, then (\w+)/.exec(w);
    $("#wd-ms").value = at ? `${at[1]}ms` : "0ms";
    if (at) $("#wd-action").value = at[2];
  }
  UI.on("view", (m) => { if (m.view === "bringup") showWatchdog(); });
  UI.on("picked", showWatchdog);
  // "horn free" is said of one servo: another picked is not (its joint's range held again).
  let freeOf = null;
  UI.on("picked", (m) => {
    if (m.id !== freeOf) { $("#br-free").checked = false; $("#mo-free").checked = false; }
    freeOf = m.id;
  });

  document.addEventListener("DOMContentLoaded", () => {
    const free = () => ($("#br-free").checked ? ["--past-limits"] : []);
    $("#br-cal").addEventListener("click", () =>
      step(["calibrate", picked()].concat($("#br-keep").checked ? ["--keep-zero"] : [], free())));
    $("#br-id").addEventListener("click", () => step(["identify", picked()].concat(free())));
    $("#br-tune").addEventListener("click", () =>
      step(["tune", picked(), "--bandwidth", $("#br-bw").value].concat($("#br-dry").checked ? ["--dry-run"] : [],
                                                                       free())));
    $("#fl-read").addEventListener("click", () => step(["faults", picked()]));
    $("#fl-clear").addEventListener("click", () => step(["faults", picked(), "--clear"]));
    $("#wd-set").addEventListener("click", async () => {
      const r = await step(["config", "set", picked(), "watchdog_action", $("#wd-action").value]);
      if (!r.code) await step(["config", "set", picked(), "watchdog_ms", $("#wd-ms").value]);
    });
    $("#up-go").addEventListener("click", () => {
      const ids = $("#up-ids").value.split(/[\s,]+/).filter((s) => s);
      const argv = ["update", ...ids, $("#up-file").value];
      if (Number($("#up-catch").value) > 0) argv.push("--catch", $("#up-catch").value);
      step(argv);
    });
  });
})();
