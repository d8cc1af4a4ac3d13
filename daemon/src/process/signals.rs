//! SIGTERM / SIGINT: the handler only sets a flag (async-signal-safe); the
//! loop sees it within one period and shuts down in order (safe hold, final
//! status, exit). Installed without SA_RESTART so a sleeping
//! `clock_nanosleep` on the signalled thread returns at once.

use std::sync::atomic::{AtomicBool, Ordering};

static STOP: AtomicBool = AtomicBool::new(false);
static SIGNAL: std::sync::atomic::AtomicI32 = std::sync::atomic::AtomicI32::new(0);

extern "C" fn on_signal(sig: libc::c_int) {
    SIGNAL.store(sig, Ordering::Relaxed);
    STOP.store(true, Ordering::Release);
}

/// Installs the handler for SIGTERM and SIGINT; returns the stop flag.
pub fn install() -> std::io::Result<&'static AtomicBool> {
    for sig in [libc::SIGTERM, libc::SIGINT] {
        // SAFETY: a zeroed sigaction is valid; the handler is async-signal-safe
        // (two atomic stores).
        unsafe {
            let mut sa: libc::sigaction = std::mem::zeroed();
            sa.sa_sigaction = on_signal as *const () as libc::sighandler_t;
            libc::sigemptyset(&mut sa.sa_mask);
            sa.sa_flags = 0;
            if libc::sigaction(sig, &sa, std::ptr::null_mut()) != 0 {
                return Err(std::io::Error::last_os_error());
            }
        }
    }
    Ok(&STOP)
}

/// The stop flag (also set by [`install`]'s handler).
pub fn stop_flag() -> &'static AtomicBool {
    &STOP
}

/// The last signal received (0 if none).
pub fn last_signal() -> i32 {
    SIGNAL.load(Ordering::Relaxed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sigterm_sets_the_flag() {
        let flag = install().unwrap();
        assert!(!flag.load(Ordering::Acquire));
        // SAFETY: raising a handled signal in our own process.
        unsafe { libc::raise(libc::SIGTERM) };
        assert!(flag.load(Ordering::Acquire));
        assert_eq!(last_signal(), libc::SIGTERM);
        flag.store(false, Ordering::Release);
    }
}
