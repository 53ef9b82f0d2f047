//! The live view's server (the `live` feature): the Foxglove WebSocket server and its
//! publisher thread.

use super::{LiveConfig, LiveError, LiveSummary};
use haptic_engine::haptic::HapticLoop;
use haptic_engine::pacing::TickStats;
use haptic_engine::sink::{SessionInfo, Sink, SinkError, TickView};
use recording::foxglove_out;

use haptic_types::Event;

use foxglove::schemas::{FrameTransform, Log, SceneUpdate};
use foxglove::{Context, PartialMetadata, RawChannel, Schema, WebSocketServerHandle};
use haptic_types::Primitive;
use haptic_types::vec3::Vec3;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

struct Snapshot {
    tick: u64,
    cursor_m: Vec3,
    world_force_n: Vec3,
    device_force_n: Vec3,
    engagement: f64,
    watchdog: f64,
    status: u8,
    age_ticks: u32,
    prims: Option<Vec<Primitive>>,
    events: Vec<Event>,
}

struct Shared {
    queue: Mutex<Vec<Snapshot>>,
    done: AtomicBool,
    dropped: AtomicU64,
    scenes: AtomicU64,
    states: AtomicU64,
    logs: AtomicU64,
}

/// Most snapshots waiting for the publisher; beyond, the oldest are dropped.
const CAP: usize = 2048;

/// The live Foxglove view of a session.
pub struct LiveSink {
    config: LiveConfig,
    menu: Arc<Mutex<super::menu::Menu>>,
    server: Option<WebSocketServerHandle>,
    guard: Option<super::guard::LiveGuard>,
    ctx: Arc<Context>,
    shared: Arc<Shared>,
    local: Vec<Snapshot>,
    thread: Option<JoinHandle<()>>,
    display_every: u64,
    plot_every: u64,
}

impl LiveSink {
    /// Starts the WebSocket server (clients may connect before the first tick).
    pub fn new(config: LiveConfig) -> Result<Self, LiveError> {
        let ctx = Context::new();
        let menu = Arc::new(Mutex::new(super::menu::Menu::default()));
        let server = ctx
            .websocket_server()
            .name("nanohaptics")
            .capabilities([foxglove::websocket::Capability::Parameters])
            .listener(Arc::new(super::menu::MenuListener(menu.clone())))
            // A private loopback port: clients reach it only through the guard.
            .bind("127.0.0.1", 0)
            .start_blocking()
            .map_err(|e| LiveError::Serve(format!("cannot serve on ws:{}: {e}", config.bind)))?;
        let backend = std::net::SocketAddr::from(([127, 0, 0, 1], server.port()));
        let guard = super::guard::LiveGuard::start(config.bind, backend)
            .map_err(|e| LiveError::Serve(format!("cannot serve on ws:{}: {e}", config.bind)))?;
        Ok(LiveSink {
            config,
            menu,
            server: Some(server),
            guard: Some(guard),
            ctx,
            shared: Arc::new(Shared {
                queue: Mutex::new(Vec::with_capacity(CAP)),
                done: AtomicBool::new(false),
                dropped: AtomicU64::new(0),
                scenes: AtomicU64::new(0),
                states: AtomicU64::new(0),
                logs: AtomicU64::new(0),
            }),
            local: Vec::with_capacity(64),
            thread: None,
            display_every: 1,
            plot_every: 1,
        })
    }

    /// The menu's queue of switches set in Foxglove (see [`menu`](super::menu)): the session
    /// applies them before the next tick.
    pub fn menu(&self) -> Arc<Mutex<super::menu::Menu>> {
        self.menu.clone()
    }

    /// The port the view is served on (useful with port 0): the guard's, which checks every
    /// connection's `Host` and `Origin` before passing it to the Foxglove server.
    pub fn port(&self) -> Option<u16> {
        self.guard.as_ref().map(|g| g.addr().port())
    }

    /// What was published so far.
    pub fn summary(&self) -> LiveSummary {
        let s = &self.shared;
        LiveSummary {
            scenes: s.scenes.load(Ordering::Relaxed),
            states: s.states.load(Ordering::Relaxed),
            logs: s.logs.load(Ordering::Relaxed),
            dropped: s.dropped.load(Ordering::Relaxed),
            clients_at_end: self.server.as_ref().map_or(0, |h| h.client_count()),
            refused_host: self
                .guard
                .as_ref()
                .map_or(0, |g| g.gate.refused.snapshot().host),
            refused_origin: self
                .guard
                .as_ref()
                .map_or(0, |g| g.gate.refused.snapshot().origin),
        }
    }

    fn hand_over(&mut self) {
        if let Ok(mut q) = self.shared.queue.try_lock() {
            q.append(&mut self.local);
            if q.len() > CAP {
                let extra = q.len() - CAP;
                q.drain(..extra);
                self.shared
                    .dropped
                    .fetch_add(extra as u64, Ordering::Relaxed);
            }
        } else if self.local.len() > CAP {
            let extra = self.local.len() - CAP;
            self.local.drain(..extra);
            self.shared
                .dropped
                .fetch_add(extra as u64, Ordering::Relaxed);
        }
    }
}

/// Tick-rate divisor nearest to `rate / hz` (at least 1).
fn every(rate_hz: u32, hz: u32) -> u64 {
    u64::from((rate_hz / hz.clamp(1, rate_hz.max(1))).max(1))
}

/// JSON schema of `/live/state`.
const STATE_SCHEMA: &str = r#"{"type":"object","properties":{
"tick":{"type":"integer"},"time_s":{"type":"number"},
"cursor_m":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},
"world_force_n":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},
"device_force_n":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},
"device_force_norm_n":{"type":"number"},"engagement":{"type":"number"},"watchdog":{"type":"number"},
"status":{"type":"integer"},"sample_age_ticks":{"type":"integer"},"dropped":{"type":"integer"}}}"#;

fn xyz(v: Vec3) -> serde_json::Value {
    serde_json::json!({"x": v[0], "y": v[1], "z": v[2]})
}

struct Channels {
    scene: foxglove::Channel<SceneUpdate>,
    tf: foxglove::Channel<FrameTransform>,
    log: foxglove::Channel<Log>,
    state: Arc<RawChannel>,
}

fn publish(
    shared: Arc<Shared>,
    ch: Channels,
    start_ns: u64,
    period_ns: u64,
    rate_hz: u32,
    scale: f64,
) {
    let mut batch = Vec::with_capacity(CAP);
    loop {
        let done = shared.done.load(Ordering::Acquire);
        if let Ok(mut q) = shared.queue.lock() {
            std::mem::swap(&mut *q, &mut batch);
        }
        for s in batch.drain(..) {
            let t_ns = start_ns.saturating_add(s.tick.saturating_mul(period_ns));
            let meta = PartialMetadata::with_log_time(t_ns);
            if let Some(prims) = &s.prims {
                let u = foxglove_out::scene_update(prims, scale, t_ns);
                ch.scene.log_with_meta(&u, meta);
                let tf = foxglove_out::cursor_transform(s.cursor_m, scale, t_ns);
                ch.tf.log_with_meta(&tf, meta);
                shared.scenes.fetch_add(1, Ordering::Relaxed);
            }
            for e in &s.events {
                ch.log
                    .log_with_meta(&foxglove_out::event_log(e, t_ns), meta);
                shared.logs.fetch_add(1, Ordering::Relaxed);
            }
            let j = serde_json::json!({
                "tick": s.tick,
                "time_s": s.tick as f64 / f64::from(rate_hz),
                "cursor_m": xyz(s.cursor_m),
                "world_force_n": xyz(s.world_force_n),
                "device_force_n": xyz(s.device_force_n),
                "device_force_norm_n": haptic_types::vec3::norm(s.device_force_n),
                "engagement": s.engagement,
                "watchdog": s.watchdog,
                "status": s.status,
                "sample_age_ticks": s.age_ticks,
                "dropped": shared.dropped.load(Ordering::Relaxed),
            });
            ch.state.log_with_meta(j.to_string().as_bytes(), meta);
            shared.states.fetch_add(1, Ordering::Relaxed);
        }
        if done {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

impl Sink for LiveSink {
    fn name(&self) -> &'static str {
        "live"
    }

    fn start(&mut self, info: &SessionInfo<'_>, lp: &HapticLoop) -> Result<(), SinkError> {
        let c = info.config;
        self.display_every = every(c.rate_hz, self.config.display_hz);
        self.plot_every = every(c.rate_hz, self.config.plot_hz);
        let ctx = &self.ctx;
        let state = ctx
            .channel_builder("/live/state")
            .message_encoding("json")
            .schema(Schema::new(
                "nanohaptics.LiveState",
                "jsonschema",
                STATE_SCHEMA.as_bytes().to_vec(),
            ))
            .build_raw()
            .map_err(|e| SinkError::from(LiveError::Serve(e.to_string())))?;
        let ch = Channels {
            scene: ctx.channel_builder("/foxglove/scene").build(),
            tf: ctx.channel_builder("/foxglove/tf").build(),
            log: ctx.channel_builder("/foxglove/log").build(),
            state,
        };
        let shared = self.shared.clone();
        let start_ns = info.header.start_time_ns;
        let (period, rate, scale) = (c.period_ns(), c.rate_hz, c.display_scale);
        let scene = lp.scene();
        let values = scene.switch_values().into_iter().collect();
        if let Ok(mut m) = self.menu.lock() {
            m.offer(scene.kind(), scene.switches(), values);
        }
        self.thread = Some(
            std::thread::Builder::new()
                .name("live-view".into())
                .spawn(move || publish(shared, ch, start_ns, period, rate, scale))
                .map_err(|e| SinkError::from(LiveError::Serve(e.to_string())))?,
        );
        Ok(())
    }

    fn tick(&mut self, t: &TickView<'_>) -> Result<(), SinkError> {
        let r = t.result;
        if !r.switches.is_empty() {
            // What the loop applied is what the menu shows (rare: a switch set this tick).
            if let Ok(mut m) = self.menu.try_lock() {
                for s in &r.switches {
                    m.set_value(&s.name, s.value);
                }
            }
        }
        let display = r.tick % self.display_every == 0;
        if r.tick % self.plot_every != 0 && !display && r.events.is_empty() {
            return Ok(());
        }
        let prims = display.then(|| {
            let mut p = Vec::new();
            t.lp.scene().draw(&mut p);
            p
        });
        self.local.push(Snapshot {
            tick: r.tick,
            cursor_m: r.cursor_m,
            world_force_n: r.world_force_n,
            device_force_n: r.device_force_n,
            engagement: r.engagement,
            watchdog: r.watchdog,
            status: r.status,
            age_ticks: t.sample.age_ticks,
            prims,
            events: r.events.clone(),
        });
        self.hand_over();
        Ok(())
    }

    fn finish(
        &mut self,
        _stats: &TickStats,
        _link: &[(&'static str, u64)],
    ) -> Result<(), SinkError> {
        if let Ok(mut q) = self.shared.queue.lock() {
            q.append(&mut self.local);
        }
        self.shared.done.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            t.join().map_err(|_| {
                SinkError::from(LiveError::Serve("the publisher thread panicked".into()))
            })?;
        }
        Ok(())
    }
}

impl Drop for LiveSink {
    fn drop(&mut self) {
        self.shared.done.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        self.guard.take();
        if let Some(s) = self.server.take() {
            drop(s.stop());
        }
    }
}
