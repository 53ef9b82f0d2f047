//! Machine facts a report states at its top: CPU model, core count, load average.
//!
//! The project quotes ratios from quiet runs only, so every section shows the load average
//! (from `/proc/loadavg`) at the start and at the end of its run.

use std::fmt;

/// The 1-, 5- and 15-minute load averages (runnable threads, averaged).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadAvg {
    /// Over the last minute.
    pub one: f64,
    /// Over the last 5 minutes.
    pub five: f64,
    /// Over the last 15 minutes.
    pub fifteen: f64,
}

impl LoadAvg {
    /// Parses the first three fields of `/proc/loadavg` text (`"0.71 1.14 0.70 1/86 13180"`).
    pub fn parse(text: &str) -> Option<Self> {
        let mut it = text.split_whitespace().map(str::parse::<f64>);
        let (one, five, fifteen) = (it.next()?.ok()?, it.next()?.ok()?, it.next()?.ok()?);
        Some(Self { one, five, fifteen })
    }

    /// The machine's load average now; `None` where `/proc/loadavg` is missing.
    pub fn now() -> Option<Self> {
        Self::parse(&std::fs::read_to_string("/proc/loadavg").ok()?)
    }
}

impl fmt::Display for LoadAvg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.2} {:.2} {:.2}", self.one, self.five, self.fifteen)
    }
}

/// The CPU model from `/proc/cpuinfo` text: the first `model name` line's value.
pub fn parse_cpu_model(cpuinfo: &str) -> Option<String> {
    cpuinfo
        .lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split_once(':'))
        .map(|(_, v)| v.trim().to_string())
        .filter(|v| !v.is_empty())
}

/// What the report ran on.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    /// CPU model (`model name` in `/proc/cpuinfo`), or "unknown CPU".
    pub cpu: String,
    /// Cores this process may use (`std::thread::available_parallelism`), 0 if unknown.
    pub cores: usize,
}

impl Machine {
    /// Reads the facts of this machine.
    pub fn detect() -> Self {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| parse_cpu_model(&s))
            .unwrap_or_else(|| "unknown CPU".to_string());
        let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
        Self { cpu, cores }
    }
}

/// The sentence a section opens with: the machine, the load at start and end, the run time.
pub fn facts_line(m: &Machine, start: Option<LoadAvg>, end: Option<LoadAvg>, run_s: f64) -> String {
    let load = |l: Option<LoadAvg>| l.map_or("unknown".to_string(), |l| format!("`{l}`"));
    format!(
        "Machine: {}, {} cores. Load average (1, 5, 15 min) at start {}, at end {}; the report ran {:.0} s.",
        m.cpu,
        m.cores,
        load(start),
        load(end),
        run_s
    )
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn parses_loadavg_and_cpuinfo() {
        let l = LoadAvg::parse("0.71 1.14 0.70 1/86 13180\n").unwrap();
        assert_eq!((l.one, l.five, l.fifteen), (0.71, 1.14, 0.70));
        assert_eq!(l.to_string(), "0.71 1.14 0.70");
        assert_eq!(LoadAvg::parse("0.71 x 0.70"), None);
        assert_eq!(LoadAvg::parse(""), None);
        let info = "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC 7B13\nflags\t: fpu\n";
        assert_eq!(parse_cpu_model(info).as_deref(), Some("AMD EPYC 7B13"));
        assert_eq!(parse_cpu_model("processor : 0\n"), None);
        assert_eq!(parse_cpu_model("model name\t:  \n"), None);
    }

    #[test]
    fn facts_line_states_machine_load_and_time() {
        let m = Machine {
            cpu: "AMD EPYC".into(),
            cores: 2,
        };
        let a = LoadAvg::parse("1.50 1.33 0.73").unwrap();
        let b = LoadAvg::parse("2.00 1.40 0.80").unwrap();
        assert_eq!(
            facts_line(&m, Some(a), Some(b), 61.4),
            "Machine: AMD EPYC, 2 cores. Load average (1, 5, 15 min) at start `1.50 1.33 0.73`, at end `2.00 1.40 0.80`; the report ran 61 s."
        );
        assert_eq!(
            facts_line(&m, None, None, 0.2),
            "Machine: AMD EPYC, 2 cores. Load average (1, 5, 15 min) at start unknown, at end unknown; the report ran 0 s."
        );
        assert!(Machine::detect().cores >= 1);
    }
}
