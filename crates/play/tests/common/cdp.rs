//! A small client of Chromium's DevTools Protocol over a WebSocket (headless Debian
//! `chromium`), for the browser tests and the play bench. Page errors (exceptions, console
//! errors, failed loads) are collected as they arrive; `check` fails on any.
#![allow(dead_code)]

use serde_json::{Value, json};
use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

/// How to install the browser the tests need.
pub const INSTALL: &str = "the browser tests need Debian's chromium: `sudo apt-get install -y \
    chromium` (scripts/test.sh installs it)";

/// A headless Chromium and one page of it.
pub struct Browser {
    child: Child,
    dir: PathBuf,
    ws: WebSocket<MaybeTlsStream<TcpStream>>,
    next: u64,
    session: String,
    /// Page errors seen so far (exceptions, console errors, failed loads).
    pub errors: Vec<String>,
    /// Events of the page not yet looked at.
    pub events: Vec<Value>,
    /// The URL of every WebSocket the page opened, in order (kept however many events come),
    /// its workers' included (the page's link is a Worker's).
    pub websockets: Vec<String>,
    /// Workers the page started, paused until their errors and sockets are watched too.
    workers: Vec<String>,
}

fn chromium() -> Result<PathBuf, String> {
    for c in ["/usr/bin/chromium", "/usr/bin/chromium-browser"] {
        if std::path::Path::new(c).exists() {
            return Ok(c.into());
        }
    }
    Err(INSTALL.to_string())
}

impl Browser {
    /// Starts a headless browser with a window of `w × h` CSS pixels and opens a blank page.
    pub fn launch(w: u32, h: u32) -> Result<Browser, String> {
        Self::launch_nice(w, h, 0)
    }

    /// [`Browser::launch`] at scheduling priority `nice` (0: normal; 19: lowest, through
    /// `nice -n`).
    pub fn launch_nice(w: u32, h: u32, nice: i32) -> Result<Browser, String> {
        let exe = chromium()?;
        // One profile directory per browser: two browsers on one profile would be one browser.
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        // Under target/, beside the test (or bench) binary.
        let here = std::env::current_exe().map_err(|e| e.to_string())?;
        let dir = here.with_file_name("test-tmp").join(format!(
            "nh-chromium-{}-{}",
            std::process::id(),
            NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
        let mut cmd = if nice != 0 {
            let mut c = Command::new("nice");
            c.args(["-n", &nice.to_string()]).arg(&exe);
            c
        } else {
            Command::new(&exe)
        };
        let mut child = cmd
            .args([
                "--headless=new",
                "--remote-debugging-port=0",
                &format!("--user-data-dir={}", dir.display()),
                "--no-sandbox",
                "--no-first-run",
                "--disable-gpu",
                "--disable-extensions",
                "--mute-audio",
                "--autoplay-policy=no-user-gesture-required",
                &format!("--window-size={w},{h}"),
                "about:blank",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("cannot start chromium: {e}; {INSTALL}"))?;
        let stderr = child.stderr.take().ok_or("no stderr")?;
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut sent = false;
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                if !sent && let Some(u) = line.strip_prefix("DevTools listening on ") {
                    let _ = tx.send(u.trim().to_string());
                    sent = true;
                }
            }
        });
        let url = rx
            .recv_timeout(Duration::from_secs(60))
            .map_err(|_| "chromium printed no DevTools URL within 60 s".to_string())?;
        let (ws, _) = tungstenite::connect(url.as_str()).map_err(|e| e.to_string())?;
        let mut b = Browser {
            child,
            dir,
            ws,
            next: 0,
            session: String::new(),
            errors: Vec::new(),
            events: Vec::new(),
            websockets: Vec::new(),
            workers: Vec::new(),
        };
        let t = b.call_browser("Target.createTarget", json!({"url": "about:blank"}))?;
        let target = t["targetId"].as_str().ok_or("no targetId")?.to_string();
        let a = b.call_browser(
            "Target.attachToTarget",
            json!({"targetId": target, "flatten": true}),
        )?;
        b.session = a["sessionId"].as_str().ok_or("no sessionId")?.to_string();
        for m in [
            "Page.enable",
            "Runtime.enable",
            "Log.enable",
            "Network.enable",
        ] {
            b.call(m, json!({}))?;
        }
        // The page's workers: each starts paused, is watched as the page is, then runs.
        b.call(
            "Target.setAutoAttach",
            json!({"autoAttach": true, "waitForDebuggerOnStart": true, "flatten": true}),
        )?;
        b.call(
            "Emulation.setDeviceMetricsOverride",
            json!({"width": w, "height": h, "deviceScaleFactor": 1, "mobile": false}),
        )?;
        Ok(b)
    }

    fn note(&mut self, v: &Value) {
        let m = v["method"].as_str().unwrap_or("");
        let p = &v["params"];
        match m {
            "Runtime.exceptionThrown" => self.errors.push(format!(
                "JavaScript exception: {}",
                p["exceptionDetails"]["exception"]["description"]
                    .as_str()
                    .or(p["exceptionDetails"]["text"].as_str())
                    .unwrap_or("?")
            )),
            "Log.entryAdded" if p["entry"]["level"] == "error" => self.errors.push(format!(
                "console error: {} {}",
                p["entry"]["text"].as_str().unwrap_or(""),
                p["entry"]["url"].as_str().unwrap_or("")
            )),
            "Runtime.consoleAPICalled" if p["type"] == "error" => {
                self.errors.push(format!("console.error: {}", p["args"]))
            }
            "Network.loadingFailed" if p["canceled"] != true => self.errors.push(format!(
                "load failed: {}",
                p["errorText"].as_str().unwrap_or("?")
            )),
            "Target.attachedToTarget" => {
                if let Some(id) = p["sessionId"].as_str() {
                    self.workers.push(id.to_string());
                }
            }
            "Network.webSocketCreated" => {
                self.websockets
                    .push(p["url"].as_str().unwrap_or("?").to_string());
            }
            "Network.responseReceived" => {
                let status = p["response"]["status"].as_u64().unwrap_or(0);
                if status >= 400 {
                    self.errors.push(format!(
                        "HTTP {status} for {}",
                        p["response"]["url"].as_str().unwrap_or("?")
                    ));
                }
            }
            _ => {}
        }
        if !m.is_empty() {
            self.events.push(v.clone());
            if self.events.len() > 1000 {
                self.events.drain(..500);
            }
        }
    }

    /// Workers (and worklets) attached since: watched as the page is, then let run, without
    /// waiting for the answers (a command may be waiting on the worker: an AudioWorklet's
    /// `addModule`).
    fn release_workers(&mut self) -> Result<(), String> {
        while let Some(w) = self.workers.pop() {
            for m in [
                "Runtime.enable",
                "Log.enable",
                "Network.enable",
                "Runtime.runIfWaitingForDebugger",
            ] {
                self.next += 1;
                let msg = json!({"id": self.next, "method": m, "params": {}, "sessionId": w});
                self.ws
                    .send(Message::text(msg.to_string()))
                    .map_err(|e| e.to_string())?;
            }
        }
        Ok(())
    }

    fn send(&mut self, method: &str, params: Value, session: bool) -> Result<Value, String> {
        self.release_workers()?;
        self.next += 1;
        let id = self.next;
        let mut msg = json!({"id": id, "method": method, "params": params});
        if session {
            msg["sessionId"] = json!(self.session);
        }
        self.ws
            .send(Message::text(msg.to_string()))
            .map_err(|e| e.to_string())?;
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            if Instant::now() > deadline {
                return Err(format!("no answer to {method} within 30 s"));
            }
            let m = self.ws.read().map_err(|e| e.to_string())?;
            let Message::Text(t) = m else { continue };
            let v: Value = serde_json::from_str(t.as_str()).map_err(|e| e.to_string())?;
            if v["id"].as_u64() == Some(id) {
                if let Some(e) = v.get("error") {
                    return Err(format!("{method}: {e}"));
                }
                return Ok(v["result"].clone());
            }
            self.note(&v);
            self.release_workers()?;
        }
    }

    fn call_browser(&mut self, method: &str, params: Value) -> Result<Value, String> {
        self.send(method, params, false)
    }

    /// A command to the page.
    pub fn call(&mut self, method: &str, params: Value) -> Result<Value, String> {
        self.send(method, params, true)
    }

    /// Opens `url` and waits for its load event; a failed navigation is an error.
    pub fn open(&mut self, url: &str) -> Result<(), String> {
        self.events.clear();
        let r = self.call("Page.navigate", json!({"url": url}))?;
        if let Some(e) = r["errorText"].as_str() {
            return Err(format!("{url} failed to load: {e}"));
        }
        let t0 = Instant::now();
        while !self
            .events
            .iter()
            .any(|e| e["method"] == "Page.loadEventFired")
        {
            if t0.elapsed() > Duration::from_secs(20) {
                return Err(format!("{url}: no load event within 20 s"));
            }
            self.eval("0")?;
            std::thread::sleep(Duration::from_millis(20));
        }
        Ok(())
    }

    /// Runs `source` in every document this page opens from now on, before the document's
    /// own scripts (a scripted browser API, e.g. a gamepad).
    pub fn inject(&mut self, source: &str) -> Result<(), String> {
        self.call(
            "Page.addScriptToEvaluateOnNewDocument",
            json!({ "source": source }),
        )
        .map(drop)
    }

    /// Evaluates a JavaScript expression in the page and returns its value (JSON).
    pub fn eval(&mut self, expr: &str) -> Result<Value, String> {
        let r = self.call(
            "Runtime.evaluate",
            json!({"expression": expr, "returnByValue": true, "awaitPromise": true}),
        )?;
        if let Some(e) = r.get("exceptionDetails") {
            return Err(format!("`{expr}` threw: {e}"));
        }
        Ok(r["result"]["value"].clone())
    }

    /// Waits until `expr` is true (polling every 20 ms) or fails after `secs`.
    pub fn wait_for(&mut self, expr: &str, secs: f64) -> Result<(), String> {
        let t0 = Instant::now();
        loop {
            if self.eval(expr)? == json!(true) {
                return Ok(());
            }
            if t0.elapsed().as_secs_f64() > secs {
                return Err(format!("`{expr}` not true within {secs} s"));
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// A mouse event (`mouseMoved`, `mousePressed`, `mouseReleased`, `mouseWheel`) at CSS
    /// pixel (x, y); `down`: the left button is held.
    pub fn mouse(
        &mut self,
        kind: &str,
        x: f64,
        y: f64,
        down: bool,
        wheel_dy: f64,
    ) -> Result<(), String> {
        let mut p = json!({"type": kind, "x": x, "y": y, "buttons": if down { 1 } else { 0 }});
        if kind == "mousePressed" || kind == "mouseReleased" {
            p["button"] = json!("left");
            p["clickCount"] = json!(1);
        }
        if kind == "mouseWheel" {
            p["deltaX"] = json!(0);
            p["deltaY"] = json!(wheel_dy);
        }
        self.call("Input.dispatchMouseEvent", p).map(drop)
    }

    /// A key pressed and let go (no Shift).
    pub fn press(&mut self, key: &str) {
        self.key(key, true, false).unwrap_or_else(|e| panic!("{e}"));
        self.key(key, false, false)
            .unwrap_or_else(|e| panic!("{e}"));
    }

    /// A key going down or up (`key` as in `KeyboardEvent.key`, e.g. `ArrowLeft`, ` `, `e`).
    pub fn key(&mut self, key: &str, down: bool, shift: bool) -> Result<(), String> {
        let (code, vk) = match key {
            "ArrowLeft" => ("ArrowLeft", 37),
            "ArrowUp" => ("ArrowUp", 38),
            "ArrowRight" => ("ArrowRight", 39),
            "ArrowDown" => ("ArrowDown", 40),
            "PageUp" => ("PageUp", 33),
            "PageDown" => ("PageDown", 34),
            "Home" => ("Home", 36),
            "End" => ("End", 35),
            "Tab" => ("Tab", 9),
            " " => ("Space", 32),
            "e" => ("KeyE", 69),
            "Enter" => ("Enter", 13),
            _ => ("", 0),
        };
        let mut p = json!({"type": if down { "rawKeyDown" } else { "keyUp" }, "key": key,
            "code": code, "windowsVirtualKeyCode": vk, "modifiers": if shift { 8 } else { 0 }});
        if down && (key.chars().count() == 1 || key == "Enter") {
            p["type"] = json!("keyDown");
            p["text"] = json!(if key == "Enter" { "\r" } else { key });
        }
        self.call("Input.dispatchKeyEvent", p).map(drop)
    }

    /// Saves a PNG screenshot of the page.
    pub fn screenshot(&mut self, path: &std::path::Path) -> Result<(), String> {
        let r = self.call("Page.captureScreenshot", json!({"format": "png"}))?;
        let data = base64_decode(r["data"].as_str().ok_or("no screenshot data")?)?;
        if let Some(d) = path.parent() {
            std::fs::create_dir_all(d).map_err(|e| e.to_string())?;
        }
        std::fs::write(path, data).map_err(|e| e.to_string())
    }

    /// Fails with the page's errors, if any.
    pub fn check(&mut self) -> Result<(), String> {
        self.eval("0")?;
        if self.errors.is_empty() {
            Ok(())
        } else {
            Err(format!("the page failed: {}", self.errors.join("; ")))
        }
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Standard base64 (with padding) to bytes.
pub fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    let val = |c: u8| -> Result<u32, String> {
        Ok(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return Err(format!("bad base64 byte {c}")),
        } as u32)
    };
    let bytes: Vec<u8> = s
        .bytes()
        .filter(|b| *b != b'=' && !b.is_ascii_whitespace())
        .collect();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for chunk in bytes.chunks(4) {
        let mut n = 0u32;
        for (i, c) in chunk.iter().enumerate() {
            n |= val(*c)? << (18 - 6 * i);
        }
        let k = chunk.len();
        out.push((n >> 16) as u8);
        if k > 2 {
            out.push((n >> 8) as u8);
        }
        if k > 3 {
            out.push(n as u8);
        }
    }
    Ok(out)
}

/// FNV-1a (32 bits) over bytes, as the page hashes the sound it receives.
pub fn fnv1a(bytes: impl IntoIterator<Item = u8>) -> u32 {
    let mut h: u32 = 0x811c_9dc5;
    for b in bytes {
        h ^= u32::from(b);
        h = h.wrapping_mul(0x0100_0193);
    }
    h
}
