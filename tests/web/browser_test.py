#!/usr/bin/env python3
"""canmotion-web in headless Chromium against canmotiond --sim: every axis of
the demo is shown, commands are refused without
--allow-commands. Exit 77 (ctest SKIP) only when chromium is not installed."""
import os, shutil, subprocess, sys, tempfile, time
if not (shutil.which("chromium") and shutil.which("chromedriver")):
    print("chromium/chromedriver not installed: skipped"); sys.exit(77)
from selenium import webdriver
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

daemon, web, config = sys.argv[1:4]
tmp = tempfile.mkdtemp()
sock = os.path.join(tmp, "d.sock")
port = str(20000 + os.getpid() % 20000)
procs = [subprocess.Popen([daemon, "--config", config, "--sim", "--socket", sock],
                          stdout=subprocess.DEVNULL)]
log = open(os.path.join(tmp, "web.log"), "w+")
procs.append(subprocess.Popen([web, "--socket", sock, "--listen", "127.0.0.1:" + port], stderr=log))
opts = webdriver.ChromeOptions()
for a in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage"):
    opts.add_argument(a)
drv = webdriver.Chrome(options=opts)
try:
    drv.get("http://127.0.0.1:%s/" % port)
    wait = WebDriverWait(drv, 15)
    for axis in ("Master", "Gear", "Cam", "Mover"):
        wait.until(lambda d: d.find_elements(By.ID, "axis-" + axis))
    # Not yet checked: positions changing (the demo's axes stand still unless
    # driven; driving them from the test through the socket is a later slice).
    drv.execute_script("window.confirm = () => true;")
    drv.find_element(By.CSS_SELECTOR, "#axis-Mover .buttons button").click()
    wait.until(lambda d: "commands are disabled" in d.find_element(By.ID, "events").text)
    log.flush(); log.seek(0)
    assert "refused command from 127.0.0.1" in log.read(), "refusal not logged"
    print("ok: 4 axes shown, command refused and logged")
finally:
    drv.quit()
    for p in procs: p.terminate(); p.wait()
