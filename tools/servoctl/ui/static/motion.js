// The Motion view: angle moves by interval or velocity, a jog slider, wheel
// mode, hold, damp and release; each one servoctl command.
"use strict";
(() => {
  const {$, runInto, picked} = UI;
  let jogBusy = false, jogNext = null;

  async function jog(angle) {
    // The slider sends its newest angle once the last move was taken: a
    // drag does not queue a move for every pixel.
    if (jogBusy) { jogNext = angle; return; }
    jogBusy = true;
    await runInto($("#motion-out"), ["move", picked(), angle, "--interval", 200]);
    jogBusy = false;
    if (jogNext !== null) { const a = jogNext; jogNext = null; jog(a); }
  }

  document.addEventListener("DOMContentLoaded", () => {
    const out = $("#motion-out");
    $("#mv-go").addEventListener("click", () => {
      const argv = ["move", picked(), $("#mv-angle").value, `--${$("#mv-how").value}`, $("#mv-value").value];
      if ($("#mv-multi").checked) argv.push("--multi-turn");
      runInto(out, argv);
    });
    $("#jog").addEventListener("input", (e) => {
      $("#jog-at").textContent = `${e.target.value} deg`;
      jog(e.target.value);
    });
    $("#wh-run").addEventListener("click", () => {
      const argv = ["wheel", picked(), "run", "--speed", $("#wh-speed").value];
      if ($("#wh-cw").checked) argv.push("--cw");
      runInto(out, argv);
    });
    $("#wh-stop").addEventListener("click", () => runInto(out, ["wheel", picked(), "stop"]));
    document.querySelectorAll("[data-stop]").forEach((b) => b.addEventListener("click",
      () => runInto(out, ["stop", picked(), "--mode", b.dataset.stop])));
    $("#origin").addEventListener("click", () => runInto(out, ["origin", picked()]));
  });
})();
