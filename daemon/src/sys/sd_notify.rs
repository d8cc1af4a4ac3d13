//! systemd notification protocol (sd_notify(3)), our own few lines: a unix
//! datagram socket connected once to `$NOTIFY_SOCKET`, after which every
//! message is one non-blocking `send` with no allocation, so the loop can
//! send `WATCHDOG=1` itself.
//!
//! Messages: `READY=1` once the services exist, `WATCHDOG=1` from the loop
//! every half watchdog period, `STATUS=…` from housekeeping, `STOPPING=1` on
//! shutdown.

use std::io;
use std::os::linux::net::SocketAddrExt;
use std::os::unix::net::{SocketAddr, UnixDatagram};
use std::time::Duration;

/// A connection to the service manager's notification socket.
#[derive(Debug)]
pub struct Notifier {
    sock: UnixDatagram,
}

impl Notifier {
    /// Connects to `$NOTIFY_SOCKET`; `Ok(None)` when not started by systemd.
    pub fn from_env() -> io::Result<Option<Self>> {
        match std::env::var_os("NOTIFY_SOCKET") {
            Some(path) => Self::connect(&path.to_string_lossy()).map(Some),
            None => Ok(None),
        }
    }

    /// Connects to a socket path; a leading `@` names an abstract socket.
    pub fn connect(path: &str) -> io::Result<Self> {
        let sock = UnixDatagram::unbound()?;
        match path.strip_prefix('@') {
            Some(name) => sock.connect_addr(&SocketAddr::from_abstract_name(name)?)?,
            None => sock.connect(path)?,
        }
        sock.set_nonblocking(true)?;
        Ok(Self { sock })
    }

    /// Sends one message (newline-separated assignments).
    pub fn send(&self, msg: &str) -> io::Result<()> {
        self.sock.send(msg.as_bytes()).map(|_| ())
    }

    /// `READY=1`.
    pub fn ready(&self) -> io::Result<()> {
        self.send("READY=1")
    }

    /// `WATCHDOG=1` (allocation-free, non-blocking).
    pub fn watchdog(&self) -> io::Result<()> {
        self.send("WATCHDOG=1")
    }

    /// `STOPPING=1`.
    pub fn stopping(&self) -> io::Result<()> {
        self.send("STOPPING=1")
    }

    /// `STATUS=<text>` (one line).
    pub fn status(&self, text: &str) -> io::Result<()> {
        self.send(&format!("STATUS={}", text.replace('\n', " ")))
    }
}

/// The watchdog period systemd expects (`$WATCHDOG_USEC`, for this process
/// if `$WATCHDOG_PID` is set); `None` when the watchdog is off.
pub fn watchdog_period() -> Option<Duration> {
    watchdog_period_from(
        std::env::var("WATCHDOG_USEC").ok().as_deref(),
        std::env::var("WATCHDOG_PID").ok().as_deref(),
        std::process::id(),
    )
}

/// [`watchdog_period`] from explicit values.
pub fn watchdog_period_from(usec: Option<&str>, pid: Option<&str>, me: u32) -> Option<Duration> {
    if let Some(pid) = pid
        && pid.trim().parse::<u32>().ok() != Some(me)
    {
        return None;
    }
    let us: u64 = usec?.trim().parse().ok()?;
    (us > 0).then(|| Duration::from_micros(us))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_arrive_on_a_real_socket() {
        let dir = test_support::scratch_dir("sdnotify");
        let path = dir.join("notify.sock");
        let server = UnixDatagram::bind(&path).unwrap();
        let n = Notifier::connect(path.to_str().unwrap()).unwrap();
        n.ready().unwrap();
        n.watchdog().unwrap();
        n.status("ticks 5\nok").unwrap();
        let mut buf = [0u8; 256];
        let mut got = Vec::new();
        for _ in 0..3 {
            let k = server.recv(&mut buf).unwrap();
            got.push(String::from_utf8_lossy(&buf[..k]).into_owned());
        }
        assert_eq!(got, ["READY=1", "WATCHDOG=1", "STATUS=ticks 5 ok"]);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn abstract_sockets_work() {
        let name = format!("gaitd-test-{}", std::process::id());
        let server =
            UnixDatagram::bind_addr(&SocketAddr::from_abstract_name(&name).unwrap()).unwrap();
        Notifier::connect(&format!("@{name}"))
            .unwrap()
            .ready()
            .unwrap();
        let mut buf = [0u8; 32];
        let k = server.recv(&mut buf).unwrap();
        assert_eq!(&buf[..k], b"READY=1");
    }

    #[test]
    fn watchdog_period_respects_the_pid() {
        assert_eq!(
            watchdog_period_from(Some("3000000"), None, 7),
            Some(Duration::from_secs(3))
        );
        assert_eq!(
            watchdog_period_from(Some("3000000"), Some("7"), 7),
            Some(Duration::from_secs(3))
        );
        assert_eq!(watchdog_period_from(Some("3000000"), Some("8"), 7), None);
        assert_eq!(watchdog_period_from(Some("0"), None, 7), None);
        assert_eq!(watchdog_period_from(None, None, 7), None);
        assert_eq!(watchdog_period_from(Some("x"), None, 7), None);
    }
}
