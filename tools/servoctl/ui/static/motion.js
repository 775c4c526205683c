// The Motion view: angle moves by interval or velocity, a jog slider, wheel
// mode, hold, damp and release; each one servoctl command.
"use strict";
(() => {
  const {$, on, send, runInto, picked} = UI;
  let jogBusy = false, jogNext = null, shownId;  // shownId: whose angle the slider shows
  // After a STOP ALL (any tab's) the slider jogs nothing until the hand on it
  // lets go: a drag or a held key went on moving the servo after another
  // tab's stop.
  let jogStopped = false, stopsSeen = null;  // the server's STOP ALL count, sent with each jog

  // The slider where the servo is (deg: the server's read, the live
  // table's): a key then nudges it a step from there. It stood at 0 deg
  // whatever the servo's angle, and a nudge threw the horn there. Off while
  // the angle is not known, or beyond the slider's turn.
  function putSlider(deg) {
    // A jog under way: the read after it says; stopped: the hand's letting go.
    if (jogBusy || jogNext !== null || jogStopped) return;
    const slider = $("#jog"), known = typeof deg === "number";
    slider.disabled = !known || Math.abs(deg) > 180;
    if (!slider.disabled) slider.value = Math.round(deg);
    $("#jog-at").textContent = !known ? "angle not read yet" :
      `${deg.toFixed(1)} deg` + (slider.disabled ? " (beyond the slider's turn: Move, multi-turn)" : "");
  }
  function readAngle() {
    if (picked() === null) putSlider(null); else send({op: "angle", id: picked()});
  }

  async function jog(angle) {
    // The slider sends its newest angle once the last move was taken: a
    // drag does not queue a move for every pixel. The server refuses one
    // beyond a step from the servo's angle (worker.JOG_MAX_DEG).
    if (jogStopped) return;
    if (jogBusy) { jogNext = angle; return; }
    jogBusy = true;
    const id = picked();
    const r = await runInto($("#motion-out"), ["move", id, angle, "--interval", 200, "--wait"],
      {op: "jog", id, angle: Number(angle), stops: stopsSeen || 0});
    jogBusy = false;
    // A jog that did not run drops the angle the slider kept meanwhile; one
    // a STOP ALL stopped or dropped (130) holds the slider until the hand
    // lets go too: the "stopped" message comes later, and a drag went on.
    if (r.code === 130) stopJogs();
    else if (r.code !== 0) jogNext = null;
    if (jogNext !== null) { const a = jogNext; jogNext = null; jog(a); }
    else readAngle();  // the slider back where the servo is: moved, or refused
  }
  // STOP ALL (this tab's or another's) forgets a jog not yet sent, and holds
  // the slider until the pointer or key on it is let go.
  function stopJogs() {
    jogNext = null;
    jogStopped = true;
    $("#jog").disabled = true;
    $("#jog-at").textContent = "stopped: let go of the slider to jog again";
  }
  function letGo() {
    if (!jogStopped) return;
    jogStopped = false;
    readAngle();
  }
  on("stopped", (m) => { stopsSeen = m.stops; stopJogs(); });
  // A tab opening tells every tab the count: one higher than this tab's is a
  // stop whose "stopped" has not come yet (a silent servo's stop takes
  // 0.7 s), and holds the slider as that would.
  on("hello", (m) => {
    if (stopsSeen !== null && m.stops > stopsSeen) stopJogs();
    stopsSeen = m.stops;
  });
  document.addEventListener("DOMContentLoaded", () => {
    $("#stop-all").addEventListener("click", stopJogs);
    document.addEventListener("pointerup", letGo);
    document.addEventListener("keyup", letGo);
  });

  // Each Motion action, then the slider where the servo is.
  const act = (argv) => runInto($("#motion-out"), argv).then(readAngle);

  on("angle", (m) => { if (m.id === picked()) putSlider(m.angle_deg); });
  on("table", (m) => {
    const row = m.rows.find((r) => r.id === picked() && !r.gone);
    if (row) putSlider(row.angle_deg);
  });
  on("picked", (m) => {  // a scan's answer picks the same servo again: the slider keeps its focus
    if (m.id === shownId) return;
    shownId = m.id;
    putSlider(null);
    if (!$("#view-motion").hidden) readAngle();
  });
  on("view", (m) => { if (m.view === "motion") readAngle(); });

  document.addEventListener("DOMContentLoaded", () => {
    $("#mv-go").addEventListener("click", () => {
      const argv = ["move", picked(), $("#mv-angle").value, `--${$("#mv-how").value}`, $("#mv-value").value];
      if ($("#mv-multi").checked) argv.push("--multi-turn");
      act(argv);
    });
    $("#jog").addEventListener("input", (e) => {
      if (jogStopped) return;
      $("#jog-at").textContent = `${e.target.value} deg`;
      jog(e.target.value);
    });
    $("#wh-run").addEventListener("click", () => {
      const argv = ["wheel", picked(), "run", "--speed", $("#wh-speed").value];
      if ($("#wh-cw").checked) argv.push("--cw");
      if ($("#mo-free").checked) argv.push("--past-limits");
      act(argv);
    });
    $("#wh-stop").addEventListener("click", () => act(["wheel", picked(), "stop"]));
    document.querySelectorAll("[data-stop]").forEach((b) => b.addEventListener("click",
      () => act(["stop", picked(), "--mode", b.dataset.stop])));
    $("#origin").addEventListener("click", () =>
      act(["origin", picked()].concat($("#mo-free").checked ? ["--past-limits"] : [])));
  });
})();
