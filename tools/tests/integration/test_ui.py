"""servoctl ui in a real browser: headless Debian chromium, driven by
Playwright, against servo_sim with 6 servos. The page loads, a scan lists
the servos, an item edited on the page is on the servo, a move moves the
simulated horn, the plot shows samples, stop-all stops a wheel, a servo
unplugged mid-session is shown gone, a second tab is told who drives, the
token and origin checks refuse, and Ctrl-C stops the server cleanly.
Horn and wheel are judged on the simulator's state and clock.

SERVO_UI_SCREENSHOTS=DIR saves a screenshot of each view there (docs/ui:
`SERVO_UI_SCREENSHOTS=docs/ui`); without it nothing is written."""
import os
import shutil
import time
from pathlib import Path

import pytest

from servoctl import image as img
from servoctl.servo import Servo
from servoctl.sim import Simulator
from ..ui_launch import CHROMIUM, UiProcess, http_status as _status, launch_chromium, navigation_ms

playwright_api = pytest.importorskip("playwright.sync_api")
IDS = [1, 2, 3, 4, 5, 6]
SHOTS = os.environ.get("SERVO_UI_SCREENSHOTS")
WAIT_MS = 30000  # host time for the page to show what the bus thread did (a bound: on failure)


@pytest.fixture(scope="module")
def browser():
    if not Path(CHROMIUM).exists():
        pytest.fail(f"no {CHROMIUM}: scripts/setup.sh installs Debian's chromium")
    with playwright_api.sync_playwright() as pw:
        context, profile = launch_chromium(pw)
        try:
            yield context
        finally:
            context.close()
            shutil.rmtree(profile, ignore_errors=True)


@pytest.fixture(scope="module")
def bench(browser, tmp_path_factory):
    files = tmp_path_factory.mktemp("ui-files")  # the only folder the page names files in
    with Simulator(ids=IDS) as sim, UiProcess(sim, ["--files", str(files)]) as ui:
        ui.files = files
        page = browser.new_page()
        page.goto(ui.url)
        yield sim, ui, browser, page
        page.close()


def _shot(page, name: str):
    if SHOTS:
        Path(SHOTS).mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(Path(SHOTS) / f"{name}.png"))


def _view(page, name: str):
    page.click(f"#tabs button[data-view={name}]")


def test_first_line_is_the_address_with_its_token(bench):
    _, ui, _, _ = bench
    assert ui.first_line.startswith("servoctl ui: http://127.0.0.1:") and len(ui.token) >= 20


def test_page_loads_and_a_scan_lists_the_servos(bench):
    _, _, _, page = bench
    page.wait_for_function("document.querySelectorAll('#bus-table tbody tr').length === 6", timeout=WAIT_MS)
    page.wait_for_function("[...document.querySelectorAll('#bus-table td.state')]"
                           ".every(td => td.textContent === 'answering')", timeout=WAIT_MS)
    assert page.inner_text("#bus-table tr[data-id='4'] td:nth-child(2)") == "0x51a00004"
    assert navigation_ms(page)["load_ms"] > 0
    assert page.inner_text("#role") == "this tab drives the bus"
    _shot(page, "bus")


def test_an_item_edited_on_the_page_is_refused_as_servoctl_says_then_set(bench):
    _, ui, _, page = bench
    _view(page, "servo")
    field = page.locator("#items tr[data-item=angle_max] input")
    field.wait_for(timeout=WAIT_MS)
    field.fill("400")
    page.evaluate(f"UI.setServos({IDS})")  # a scan's answer meanwhile, the same servos: the edit kept
    field.press("Enter")
    why = page.locator("#items tr[data-item=angle_max] td.why")
    why.filter(has_text="servoctl: error: angle_max (51) must be").wait_for(timeout=WAIT_MS)
    field.fill("120")
    field.press("Enter")
    why.filter(has_text="angle_max = 120.0 deg").wait_for(timeout=WAIT_MS)
    assert "RAM" in page.inner_text("#items tr[data-item=watchdog_ms]")
    page.click("#cfg-diff")  # with factory
    page.locator("#servo-out", has_text="angle_max").wait_for(timeout=WAIT_MS)
    assert "120.0 deg" in page.inner_text("#servo-out")
    page.fill("#bk-file", str(ui.files / "bus.json"))
    page.click("#bk-save")
    page.locator("#servo-out", has_text="saved 6 servo(s) (1, 2, 3, 4, 5, 6)").wait_for(timeout=WAIT_MS)
    page.click("#bk-restore")
    page.locator("#servo-out", has_text="restored 6 servo(s)").wait_for(timeout=WAIT_MS)
    page.fill("#bk-file", "/etc/passwd")  # outside the ui's folder (--files): refused, said on the page
    page.click("#bk-restore")
    page.locator("#servo-out", has_text=f"the page names files in {ui.files} only").wait_for(timeout=WAIT_MS)
    _shot(page, "servo")  # read back at the end, on the servo (test_ctrl_c_...)


def test_the_plot_shows_samples(bench):
    _, _, _, page = bench
    _view(page, "plots")
    page.check("#plot-ids input[value='1']")
    page.check("#plot-ids input[value='2']")
    page.click("#plot-start")
    page.wait_for_function("servoUiPlots.count() >= 100", timeout=WAIT_MS)
    rates = page.evaluate("servoUiPlots.rates()")
    assert set(rates) == {"1", "2"} and all(r > 0 for r in rates.values())
    head, first = page.evaluate("servoUiPlots.csv()").splitlines()[:2]
    assert head.startswith("t_s,id,angle_deg,target_deg") and first.split(",")[1] in ("1", "2")
    page.click("#plot-pause")
    assert page.evaluate("servoUiPlots.paused()")
    page.click("#plot-pause")


def test_a_move_on_the_page_moves_the_horn(bench):
    sim, _, _, page = bench
    _view(page, "motion")
    page.fill("#mv-angle", "45")
    page.fill("#mv-value", "300")
    page.click("#mv-go")
    sim.wait_until(lambda: abs(sim.state(1)["angle"] - 45) < 1.0, timeout_s=10)
    _shot(page, "motion")
    _view(page, "plots")  # sampled since the last test: the move on its plots
    page.wait_for_timeout(300)
    _shot(page, "plots")


def test_stop_all_stops_a_wheel(bench):
    sim, _, _, page = bench
    page.evaluate("UI.run(['wheel', 3, 'run', '--speed', 180])")
    sim.wait_until(lambda: abs(sim.state(3)["velocity"]) > 100, timeout_s=10)
    page.select_option("#stop-mode", "damping")
    page.click("#stop-all")  # on every view's header
    sim.wait_until(lambda: abs(sim.state(3)["velocity"]) < 2, timeout_s=10)
    page.locator("#log div", has_text="stop-all: 6 of 6 servo(s) damped").wait_for(timeout=WAIT_MS)


def test_stop_all_ends_a_running_command_first(bench):
    """A move that waits for its arrival is cut short: stop-all does not
    wait behind it."""
    sim, _, _, page = bench
    page.evaluate("() => { window.waiting = UI.run(['move', 1, -90, '--interval', 8000, '--wait']); }")
    sim.wait_until(lambda: sim.state(1)["angle"] < 35, timeout_s=10)
    page.click("#stop-all")  # damping, as chosen before
    said = page.evaluate("window.waiting")
    assert said["code"] == 130 and "servoctl: interrupted by stop-all" in said["err"], said
    sim.wait_until(lambda: abs(sim.state(1)["velocity"]) < 2, timeout_s=10)
    assert sim.state(1)["angle"] > -60


def test_refused_and_dropped_requests_are_said_in_their_own_box(bench):
    """A full queue's refusal was in the footer log only, a move dropped by
    STOP ALL showed its command line alone, a scan refused or dropped said
    "scanning…" for ever, a dropped Read every item nothing: each is said
    where that action's output goes."""
    sim, _, _, page = bench
    _view(page, "bus")  # the other views' boxes are hidden, not gone
    page.evaluate("() => { window.waiting = UI.run(['move', 1, 90, '--interval', 20000, '--wait']); }")
    sim.wait_until(lambda: abs(sim.state(1)["velocity"]) > 1, timeout_s=10)  # the bus thread is in it
    page.evaluate("""() => {
        document.querySelector('#mv-angle').value = '-30';
        document.querySelector('#mv-go').click();      // queued: 1
        document.querySelector('#scan').click();       // 2
        document.querySelector('#items-read').click(); // 3
        for (let i = 0; i < 61; i++) UI.run(['ping', 2]);  // 64: the queue is full
        document.querySelector('#cfg-diff').click();   // refused
    }""")
    refused = "actions are waiting for the bus: this one is refused"
    page.locator("#servo-out", has_text=refused).wait_for(state="attached", timeout=WAIT_MS)
    page.click("#scan")  # refused too
    page.locator("#scan-line", has_text=refused).wait_for(state="attached", timeout=WAIT_MS)
    page.click("#stop-all")
    not_run = "servoctl ui: not run: stop-all came first"
    page.locator("#motion-out", has_text=not_run).wait_for(state="attached", timeout=WAIT_MS)
    page.locator("#scan-line", has_text=not_run).wait_for(state="attached", timeout=WAIT_MS)
    page.locator("#items tbody", has_text=not_run).wait_for(state="attached", timeout=WAIT_MS)
    assert page.evaluate("window.waiting")["code"] == 130
    assert sim.state(1)["angle"] > -25  # the dropped move to -30 never ran
    said = page.evaluate("UI.run(['move', null, 5])")  # no servo in the picker
    assert said["code"] == 2 and "no servo picked: scan found none" in said["err"], said
    page.click("#scan")  # the page's list again, for the tests after
    page.locator("#scan-line", has_text="6 ID(s) answered").wait_for(timeout=WAIT_MS)


def test_a_servo_unplugged_mid_session_is_shown_gone(bench):
    sim, _, _, page = bench
    page.evaluate("servoUiPlots && UI.send({op: 'plot', ids: []})")
    _view(page, "bus")
    assert sim.control("unplug 1 5").strip() == "ok"
    try:
        page.locator("#bus-table tr.gone[data-id='5'] td.state", has_text="gone: ").wait_for(timeout=WAIT_MS)
    finally:
        sim.control("unplug 0 5")
    page.locator("#bus-table tr[data-id='5']:not(.gone)").wait_for(timeout=WAIT_MS)


def test_bring_up_updates_two_servos_in_a_row_and_reads_faults(bench):
    sim, ui, _, page = bench
    image = ui.files / "firmware-0x0042.img"
    image.write_bytes(img.build(bytes(range(256)) * 6, 0x0042, img.BOARDS["host_sim"]))
    page.select_option("#stop-mode", "release")  # an update restarts a servo: never one that holds
    page.click("#stop-all")
    page.locator("#log div", has_text="stop-all: 6 of 6 servo(s) released").wait_for(timeout=WAIT_MS)
    _view(page, "bringup")
    page.fill("#up-file", str(image))
    page.fill("#up-ids", "5 6")
    page.click("#up-go")
    out = page.locator("#bringup-out")
    page.wait_for_function("document.querySelector('#bringup-out').textContent.includes('servo 6:')",
                           timeout=30000)
    assert "servo 6: version 0x0010 -> 0x0042" in out.inner_text(), out.inner_text()
    assert "servo 5: version 0x0010 -> 0x0042" in out.inner_text()
    done, _, total = page.inner_text("#up-at").removeprefix("servo 6: ").split()[:3]
    assert done == total  # the progress shown reached the whole image
    assert [sim.state(i)["version"] for i in (5, 6)] == [0x42, 0x42]
    _shot(page, "bringup")
    page.click("#fl-read")
    out.filter(has_text="servo 1: no faults").wait_for(timeout=WAIT_MS)


def test_bring_up_buttons_stay_off_while_a_step_runs(bench):
    """The live table's redraw (each second) turned them back on mid-step:
    a second step's output mixed into the first's box, the bar hid."""
    _, _, _, page = bench
    _view(page, "bringup")
    # One turn of the page's script: a step started, then a live table of
    # this firmware's servo (what greyOwn re-enabled the buttons on).
    seen = page.evaluate("""() => {
        document.querySelector('#fl-read').click();
        UI.handle({type: 'table', rows: [Object.assign({}, UI.state.servos[UI.picked()].info)]});
        return {on: [...document.querySelectorAll('#view-bringup button')].filter((b) => !b.disabled)
                    .map((b) => b.id), bar: !document.querySelector('#br-prog').hidden}; }""")
    assert seen == {"on": [], "bar": True}, seen
    page.locator("#bringup-out", has_text="no faults").wait_for(timeout=WAIT_MS)
    page.wait_for_function("!document.querySelector('#fl-read').disabled"
                           " && document.querySelector('#br-prog').hidden", timeout=WAIT_MS)


def test_the_maker_firmware_s_missing_features_are_greyed_with_the_reason(bench):
    """servoctl info of a servo that answers none of items 64-67 (the
    maker's firmware) has no winding_c: the page greys what needs them."""
    _, _, context, _ = bench
    page = context.new_page()  # a watching tab: nothing it does reaches the bus
    try:
        page.goto(bench[1].url)
        page.wait_for_function("UI.state.about.port !== undefined", timeout=WAIT_MS)
        # One turn of the page's script: the server's next live table (this
        # firmware's, every second) cannot come in between.
        seen = page.evaluate("""() => { UI.setServos([1]); UI.handle({type: 'table', rows: [{id: 1,
            voltage_v: 7.4, current_a: 0, power_w: 0, temperature_adc: 2048, temperature_c: 25, status: [],
            angle_deg: 0, turns: 0, model: 3840, firmware: 16, serial: 1}]});
            const f = [...document.querySelectorAll('#view-bringup fieldset')].find(
                (x) => x.textContent.includes('Fault history'));
            return {off: f.classList.contains('off'), why: f.dataset.why,
                    disabled: document.querySelector('#fl-read').disabled}; }""")
        assert seen["off"] and seen["disabled"] and "items 64-67 (the maker's firmware)" in seen["why"], seen
    finally:
        page.close()


def test_a_second_tab_is_told_who_drives(bench):
    _, ui, context, _ = bench
    second = context.new_page()
    try:
        second.goto(ui.url)
        second.locator("#role", has_text="drives the bus").wait_for(timeout=WAIT_MS)
        assert "watching: the tab opened at" in second.inner_text("#role")
        # Its controls out of reach of mouse and keyboard; a request it sends anyway is answered.
        assert second.evaluate("document.querySelector('main').inert")
        said = second.evaluate("UI.run(['ping', 1])")
        assert said["code"] == 2 and "drives the bus" in said["err"], said
        second.locator("#bus-table tbody tr[data-id='6']").wait_for(timeout=WAIT_MS)  # the last scan's
        second.select_option("#stop-mode", "release")
        second.click("#stop-all")  # a watching tab may still stop every servo
        second.locator("#log div", has_text="stop-all: 6 of 6 servo(s) released").wait_for(timeout=WAIT_MS)
        second.evaluate("UI.handle({type: 'scan', found: [], err: 'servoctl: interrupted by stop-all', code: 130})")
        assert "the list is partial" in second.inner_text("#scan-line")  # this tab's page only
    finally:
        second.close()


def test_no_token_or_another_origin_is_refused(bench):
    _, ui, _, _ = bench
    assert _status(ui.url) == 200
    assert _status(ui.base + "/") == 403
    assert _status(ui.base + "/?token=" + "x" * len(ui.token)) == 403
    assert _status(ui.base + "/static/app.js") == 403
    assert _status(ui.url, origin="http://evil.example") == 403
    ws = ui.base + "/ws?token=" + ui.token
    assert _status(ws, origin="http://evil.example") == 403
    assert _status(ws) == 403  # a WebSocket without an Origin
    port = ui.base.rsplit(":", 1)[1]
    assert _status(ui.url, host=f"evil.example:{port}") == 403  # a name rebound to 127.0.0.1
    assert _status(ui.url, host=f"localhost:{port}") == 200


def test_ctrl_c_stops_cleanly_and_the_edit_is_on_the_servo(bench):
    sim, ui, _, _ = bench
    code, err = ui.stop()
    assert code == 0 and "servoctl ui: stopped" in err, err
    with sim.bus() as bus:
        assert Servo(bus, 1).read("angle_max") == 1200


def test_a_shared_id_is_shown_and_one_servo_given_a_free_id_by_its_serial(browser):
    """Two servos at ID 1 answer at once and garble each other (as real
    ones do), so no serial comes through; the user types one's (its label)."""
    with Simulator(ids=[1, 1, 2]) as sim, UiProcess(sim) as ui:
        page = browser.new_page()
        try:
            page.goto(ui.url)
            row = page.locator("#bus-table tr.shared[data-id='1']")
            row.locator("td.state", has_text="ID 1 shared").wait_for(timeout=WAIT_MS)
            # Numbering them fails while both are on the bus: the page keeps servoctl's reason
            # (the scan after it must not put it out of sight).
            page.eval_on_selector("#bus-table tr.shared input.serial", "(e) => { e.dataset.old = '1'; }")
            page.fill("#bu-from", "1")
            page.fill("#bu-wait", "1")
            page.click("#bu-go")
            page.locator("#log div", has_text="id bringup").wait_for(timeout=WAIT_MS)
            page.wait_for_function("(() => { const e = document.querySelector('#bus-table tr.shared input.serial');"
                                   " return e && !e.dataset.old; })()", timeout=WAIT_MS)  # the scan after it
            page.locator("#view-bus", has_text="no servo alone at ID 1 within 1 s").wait_for(timeout=WAIT_MS)
            row.locator("input.serial").fill("0x51a00101")
            row.locator("input.new-id").fill("7")
            # Servo 2's live table redraws (each second) while the user is at the row: the row
            # stays in the page (taken out and put back, it lost its field's focus and a click
            # whose press and release straddled a redraw), and what was typed stays.
            page.eval_on_selector("#bus-table tr.shared", "(e) => { e.kept = 1; window.seen = UI.state.servos[2]; }")
            page.wait_for_function("UI.state.servos[2] !== window.seen", timeout=WAIT_MS)
            assert page.evaluate("document.querySelector('#bus-table tr.shared').kept === 1"
                                 " && document.activeElement.classList.contains('new-id')")
            _shot(page, "shared")
            row.locator("button").click()
            page.locator("#bus-table tr[data-id='7'] td.state", has_text="answering").wait_for(timeout=WAIT_MS)
            assert page.locator("#bus-table tr.shared").count() == 0
        finally:
            page.close()
            ui.stop()
        with sim.bus() as bus:
            assert Servo(bus, 7).read("serial") == 0x51A00101
