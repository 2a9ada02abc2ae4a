#!/usr/bin/env python3
"""The QA report and the server's page in a real browser: headless Chromium (SwiftShader WebGL, no GPU) driven by
Selenium, one browser for every check.

  * `k4reg align ... --report` and `k4reg align-project ... --report` write self-contained pages (no network
    address, under 40 MB) that load with no console error, draw a non-blank 3D view, show the figures of the
    command's --json, and change the picture when a scan is toggled;
  * GET / on k4reg-server serves the page; uploading two scans through it (multipart, progress events) gives the
    CLI's transform, and a project upload gives the CLI's poses.

usage: browser_test.py --k4reg BIN --server BIN --data-dir tests/data/bunny [--screenshots DIR]
Needs Debian's chromium, chromium-driver and python3-selenium."""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.support.ui import Select

FLAGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync", "--use-gl=angle",
         "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--window-size=1280,900"]
# SwiftShader reports reading pixels back (our checks do) as a performance warning; nothing of ours.
HARMLESS = re.compile(r"GPU stall due to ReadPixels")
PAIR = ("bun045.ply", "bun000.ply")
PROJECT = ("bun000.ply", "bun045.ply", "bun090.ply", "bun315.ply")
PARAMS = ["--min-scale", "0.002", "--seed", "1"]

failures = []


def check(condition, what):
    print(("ok    " if condition else "FAIL  ") + what)
    if not condition:
        failures.append(what)


def start_browser(work):
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for flag in FLAGS:
        options.add_argument(flag)
    options.add_argument("--user-data-dir=" + tempfile.mkdtemp(prefix="chromium-", dir=work))
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    options.add_experimental_option("prefs", {"download.default_directory": os.path.join(work, "downloads"),
                                              "download.prompt_for_download": False,
                                              "profile.default_content_setting_values.automatic_downloads": 1})
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    driver.set_script_timeout(60)
    return driver


def wait_for(driver, script, timeout_s, what):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if driver.execute_script(script):
            return
        time.sleep(0.1)
    raise AssertionError(f"timed out after {timeout_s} s waiting for {what}")


def console_problems(driver):
    return [entry["message"] for entry in driver.get_log("browser")
            if entry["level"] in ("SEVERE", "WARNING") and not HARMLESS.search(entry["message"])]


def lit_pixels(driver):
    """Pixels of the 3D view that differ from its background (its first pixel)."""
    return driver.execute_script("""
        const gl = document.getElementById('view3d');
        const c = document.createElement('canvas'); c.width = gl.width; c.height = gl.height;
        const g = c.getContext('2d'); g.drawImage(gl, 0, 0);
        const d = g.getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4)
          if (Math.abs(d[i] - d[0]) + Math.abs(d[i + 1] - d[1]) + Math.abs(d[i + 2] - d[2]) > 30) n++;
        return n;""")


def text(driver, element_id):
    return driver.find_element("id", element_id).text.strip()


def js_precision(value):
    """JavaScript's Number.toPrecision(6), which the page uses for its figures."""
    return driver_global.execute_script("return Number(arguments[0]).toPrecision(6)", value)


def numbers(block):
    return [float(v) for v in block.split()]


def close(a, b, tolerance=1e-9):
    return len(a) == len(b) and all(abs(x - y) <= tolerance * max(1.0, abs(y)) for x, y in zip(a, b))


def run_cli(args, work):
    out = subprocess.run(args, capture_output=True, text=True, cwd=work, timeout=300)
    if out.returncode != 0:
        sys.exit(f"{' '.join(args)} failed: {out.stderr}")
    return json.loads(out.stdout)


def check_self_contained(path):
    page = open(path, encoding="utf-8").read()
    check(not re.search(r"https?://", page), f"{os.path.basename(path)} references no network address")
    size_mb = os.path.getsize(path) / 1e6
    check(size_mb < 40, f"{os.path.basename(path)} is {size_mb:.1f} MB (< 40 MB)")


def open_report(driver, path):
    driver.get_log("browser")  # start with an empty log
    driver.get("file://" + path)
    wait_for(driver, "return !!(window.k4regView && window.k4regView.ready)", 60, "the report's first frame")


def check_toggle(driver, name):
    before_pixels, before_points = lit_pixels(driver), driver.execute_script("return window.k4regView.pointsShown")
    driver.find_element("css selector", '.cloud-toggle[data-cloud="0"]').click()
    after_pixels, after_points = lit_pixels(driver), driver.execute_script("return window.k4regView.pointsShown")
    check(after_points < before_points and after_pixels != before_pixels,
          f"{name}: hiding scan 0 changes the picture ({before_points} -> {after_points} points, "
          f"{before_pixels} -> {after_pixels} lit pixels)")
    driver.find_element("css selector", '.cloud-toggle[data-cloud="0"]').click()


def check_pair_report(driver, k4reg, data, work, shots):
    path = os.path.join(work, "r.html")
    result = run_cli([k4reg, "align", os.path.join(data, PAIR[0]), os.path.join(data, PAIR[1]), *PARAMS,
                      "--report", path, "--json"], work)
    check_self_contained(path)
    open_report(driver, path)
    check(text(driver, "rmse") == js_precision(result["rmse_m"]), f"pair report: RMSE {text(driver, 'rmse')} as --json")
    check(text(driver, "overlap-value") == js_precision(result["overlap"]), "pair report: overlap as --json")
    check(close(numbers(text(driver, "transform")), result["transform"]), "pair report: the transform of --json")
    check(("ambiguous" in text(driver, "verdict").lower()) == result["ambiguous"], "pair report: the ambiguous verdict")
    pixels = lit_pixels(driver)
    check(pixels > 1000, f"pair report: the 3D view is not blank ({pixels} lit pixels)")
    check_toggle(driver, "pair report")
    Select(driver.find_element("id", "color-mode")).select_by_value("distance")
    driver.execute_script("window.k4regView.render()")
    check(lit_pixels(driver) > 1000, "pair report: coloured by residual distance, still drawn")
    Select(driver.find_element("id", "color-mode")).select_by_value("scan")
    if shots:
        driver.execute_script("window.k4regView.render()")
        driver.save_screenshot(os.path.join(shots, "report-pair.png"))
    problems = console_problems(driver)
    check(not problems, f"pair report: no console errors or warnings {problems[:3]}")
    return result


def check_project_report(driver, k4reg, data, work, shots):
    path = os.path.join(work, "p.html")
    result = run_cli([k4reg, "align-project", *[os.path.join(data, s) for s in PROJECT], *PARAMS,
                      "--report", path, "--json"], work)
    check_self_contained(path)
    open_report(driver, path)
    check(text(driver, "global-rmse") == js_precision(result["global_rmse_m"]), "project report: global RMSE as --json")
    check(text(driver, "scans-registered") == str(result["scans_registered"]), "project report: scans registered")
    rows = driver.find_elements("css selector", "#link-table tbody tr")
    check(len(rows) == len(result["links"]), f"project report: one row per link ({len(rows)})")
    check(len(driver.find_elements("id", "link-graph")) == 1, "project report: the link graph is there")
    poses = driver.find_elements("css selector", "#poses pre.pose")
    registered = [s for s in result["scans"] if s["registered"]]
    check(len(poses) == len(registered), "project report: one pose per registered scan")
    check(all(close(numbers(p.text), s["pose"]) for p, s in zip(poses, registered)), "project report: the poses of --json")
    pixels = lit_pixels(driver)
    check(pixels > 1000, f"project report: the 3D view is not blank ({pixels} lit pixels)")
    check_toggle(driver, "project report")
    if shots:
        driver.save_screenshot(os.path.join(shots, "report-project.png"))
        driver.execute_script("document.getElementById('link-graph').scrollIntoView()")
        driver.save_screenshot(os.path.join(shots, "report-project-links.png"))
    problems = console_problems(driver)
    check(not problems, f"project report: no console errors or warnings {problems[:3]}")
    return result


def start_server(binary, work):
    port_file = os.path.join(work, "http-port")
    log = open(os.path.join(work, "server.log"), "w")
    process = subprocess.Popen([binary, "--grpc-listen", "127.0.0.1:0", "--http-listen", "127.0.0.1:0",
                                "--http-port-file", port_file, "--workers", "1", "--spool-dir", work], stderr=log)
    deadline = time.monotonic() + 20
    while not os.path.exists(port_file) or not open(port_file).read().strip():
        if process.poll() is not None or time.monotonic() > deadline:
            sys.exit("k4reg-server did not start: " + open(log.name).read())
        time.sleep(0.05)
    return process, int(open(port_file).read())


def download(driver, work, button, name):
    """Clicks a download button; the downloaded file's path once it is complete."""
    path = os.path.join(work, "downloads", name)
    driver.find_element("id", button).click()
    deadline = time.monotonic() + 30
    while not os.path.exists(path) or os.path.exists(path + ".crdownload"):
        if time.monotonic() > deadline:
            raise AssertionError(f"{name} was not downloaded")
        time.sleep(0.1)
    time.sleep(0.2)  # the rename has happened; let the writer close it
    return path


def fill_parameters(driver):
    """The page's parameter fields as the CLI runs used them (PARAMS)."""
    for field, value in (("min-scale", "0.002"), ("seed", "1")):
        element = driver.find_element("id", field)
        element.clear()
        element.send_keys(value)


def submit_and_wait(driver, what):
    driver.find_element("id", "submit").click()
    wait_for(driver, "return !!(window.k4regView && window.k4regView.ready && window.k4regView.document)", 180,
             what + " through the page")


def check_page(driver, server, data, work, pair_result, project_result, shots):
    process, port = start_server(server, work)
    try:
        driver.get_log("browser")
        driver.get(f"http://127.0.0.1:{port}/")
        wait_for(driver, "return !!document.getElementById('submit')", 20, "the page")
        driver.find_element("id", "source-file").send_keys(os.path.join(data, PAIR[0]))
        driver.find_element("id", "target-file").send_keys(os.path.join(data, PAIR[1]))
        fill_parameters(driver)
        submit_and_wait(driver, "a pair upload")
        shown = numbers(text(driver, "transform"))
        check(close(shown, pair_result["transform"]), "page: the uploaded pair gets the CLI's transform")
        check(text(driver, "rmse") == js_precision(pair_result["rmse_m"]), "page: the CLI's RMSE")
        check(driver.find_element("id", "upload-progress").get_attribute("value") == "1", "page: upload progress reached 1")
        check(lit_pixels(driver) > 1000, "page: the 3D view is not blank")
        if shots:
            driver.save_screenshot(os.path.join(shots, "page-pair.png"))
        transform = numbers(open(download(driver, work, "download-transform", "transform.txt")).read())
        check(close(transform, pair_result["transform"]), "page: the downloaded transform is the CLI's")
        report = download(driver, work, "download-report", "report.html")
        check_self_contained(report)
        page_url = driver.current_url
        open_report(driver, report)
        check(text(driver, "rmse") == js_precision(pair_result["rmse_m"]) and lit_pixels(driver) > 1000,
              "page: the downloaded report opens offline with the CLI's RMSE and a non-blank view")
        problems = console_problems(driver)
        check(not problems, f"downloaded report: no console errors or warnings {problems[:3]}")
        driver.get(page_url)
        wait_for(driver, "return !!document.getElementById('submit')", 20, "the page again")

        # A project: one multiple-file input, in the CLI's scan order.
        driver.execute_script("window.k4regView = null")
        driver.find_element("id", "mode-project").click()
        fill_parameters(driver)
        driver.find_element("id", "scan-files").send_keys("\n".join(os.path.join(data, s) for s in PROJECT))
        submit_and_wait(driver, "a project upload")
        poses = driver.find_elements("css selector", "#poses pre.pose")
        registered = [s for s in project_result["scans"] if s["registered"]]
        check(len(poses) == len(registered) and all(close(numbers(p.text), s["pose"]) for p, s in zip(poses, registered)),
              "page: the uploaded project gets the CLI's poses")
        problems = console_problems(driver)
        check(not problems, f"page: no console errors or warnings {problems[:3]}")
    finally:
        process.terminate()
        process.wait(timeout=30)


def main():
    global driver_global
    parser = argparse.ArgumentParser()
    parser.add_argument("--k4reg", required=True)
    parser.add_argument("--server", required=True)
    parser.add_argument("--data-dir", required=True)
    parser.add_argument("--screenshots", help="save screenshots here (docs/)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="k4reg-browser-") as work:
        driver = driver_global = start_browser(work)
        try:
            pair = check_pair_report(driver, args.k4reg, args.data_dir, work, args.screenshots)
            project = check_project_report(driver, args.k4reg, args.data_dir, work, args.screenshots)
            check_page(driver, args.server, args.data_dir, work, pair, project, args.screenshots)
        finally:
            driver.quit()
    if failures:
        sys.exit(f"{len(failures)} browser check(s) failed")
    print("every browser check passed")


if __name__ == "__main__":
    main()
