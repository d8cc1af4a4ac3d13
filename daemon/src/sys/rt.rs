//! Real-time setup (SPEC §7.1): memory locking, SCHED_FIFO, CPU affinity.
//!
//! Each step is tried when configured and reports why it could not be done;
//! the daemon then warns and runs without it (a developer's machine, a
//! container without CAP_SYS_NICE), it never refuses to start.

use std::io;

/// Why memory locking was skipped or failed.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// RLIMIT_MEMLOCK is finite and we are not privileged: with MCL_FUTURE
    /// every later mapping beyond the limit would fail, so we do not lock.
    #[error(
        "RLIMIT_MEMLOCK is {0} bytes; not locking memory (set LimitMEMLOCK=infinity in the unit, or grant CAP_IPC_LOCK)"
    )]
    LimitTooLow(u64),
    /// mlockall failed.
    #[error("mlockall failed: {0}")]
    Os(io::Error),
}

fn memlock_limit() -> io::Result<libc::rlim_t> {
    let mut r = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: valid out pointer.
    if unsafe { libc::getrlimit(libc::RLIMIT_MEMLOCK, &mut r) } != 0 {
        return Err(io::Error::last_os_error());
    }
    Ok(r.rlim_cur)
}

/// Whether locking all current and future memory is safe: root (which
/// bypasses the limit) or an unlimited RLIMIT_MEMLOCK.
pub fn may_lock_memory(euid: u32, limit: libc::rlim_t) -> Result<(), LockError> {
    if euid == 0 || limit == libc::RLIM_INFINITY {
        Ok(())
    } else {
        Err(LockError::LimitTooLow(limit))
    }
}

/// Locks all current and future pages (mlockall MCL_CURRENT | MCL_FUTURE),
/// so the loop never waits for a page fault.
pub fn lock_memory() -> Result<(), LockError> {
    // SAFETY: geteuid has no preconditions.
    let euid = unsafe { libc::geteuid() };
    may_lock_memory(euid, memlock_limit().map_err(LockError::Os)?)?;
    // SAFETY: plain syscall.
    if unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) } != 0 {
        return Err(LockError::Os(io::Error::last_os_error()));
    }
    Ok(())
}

/// Runs the calling thread with SCHED_FIFO at `priority` (1–99).
pub fn set_fifo_priority(priority: u32) -> io::Result<()> {
    // SAFETY: pthread_self is always a valid, running thread.
    unsafe { set_thread_fifo_priority(libc::pthread_self(), priority) }
}

/// Runs `thread` with SCHED_FIFO at `priority` (1–99).
///
/// # Safety
/// `thread` must be a thread that has not been joined or detached (e.g.
/// from a live `JoinHandle`).
pub unsafe fn set_thread_fifo_priority(thread: libc::pthread_t, priority: u32) -> io::Result<()> {
    let param = libc::sched_param {
        sched_priority: priority as libc::c_int,
    };
    // SAFETY: the caller guarantees `thread`; param is a valid pointer.
    let rc = unsafe { libc::pthread_setschedparam(thread, libc::SCHED_FIFO, &param) };
    if rc != 0 {
        return Err(io::Error::from_raw_os_error(rc));
    }
    Ok(())
}

/// What became of the loop's and the writer's SCHED_FIFO requests (`None`:
/// not attempted).
#[derive(Debug)]
pub struct FifoSetup {
    /// The loop thread's request.
    pub loop_thread: Option<io::Result<()>>,
    /// The writer thread's request.
    pub writer: Option<io::Result<()>>,
}

/// Raises the loop to SCHED_FIFO `loop_priority` with `raise_loop`, then,
/// only if that worked, the writer to `writer_priority` with
/// `raise_writer` (0 for either: not attempted). A real-time writer under a
/// normal loop would keep the loop it waits for off a shared CPU.
pub fn raise_loop_then_writer(
    loop_priority: u32,
    writer_priority: u32,
    raise_loop: impl FnOnce(u32) -> io::Result<()>,
    raise_writer: impl FnOnce(u32) -> io::Result<()>,
) -> FifoSetup {
    if loop_priority == 0 {
        return FifoSetup {
            loop_thread: None,
            writer: None,
        };
    }
    let loop_thread = raise_loop(loop_priority);
    let writer =
        (loop_thread.is_ok() && writer_priority > 0).then(|| raise_writer(writer_priority));
    FifoSetup {
        loop_thread: Some(loop_thread),
        writer,
    }
}

/// Restricts the calling thread to `cpus` (no-op for an empty list).
pub fn pin_current_thread(cpus: &[u32]) -> io::Result<()> {
    if cpus.is_empty() {
        return Ok(());
    }
    // SAFETY: cpu_set_t is plain data; CPU_ZERO/CPU_SET write within it
    // (config validation keeps CPU numbers below CPU_SETSIZE = 1024).
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_ZERO(&mut set);
        for &c in cpus {
            libc::CPU_SET(c as usize, &mut set);
        }
        if libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) != 0 {
            return Err(io::Error::last_os_error());
        }
    }
    Ok(())
}

/// Sets the calling thread's timer slack to 1 ns: a normal (non-real-time)
/// thread's absolute sleeps otherwise end up to 50 µs late (the kernel's
/// default slack, which it applies to SCHED_OTHER threads only). Best
/// effort: failure leaves the default.
pub fn precise_timers() {
    // SAFETY: PR_SET_TIMERSLACK takes an integer argument; no pointers.
    unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong) };
}

/// Touches `bytes` of stack so its pages are mapped (and locked) before
/// the loop starts.
#[inline(never)]
pub fn prefault_stack(bytes: usize) {
    let mut buf = [0u8; 64 * 1024];
    let n = bytes.min(buf.len());
    for i in (0..n).step_by(4096) {
        // Volatile so the writes are not optimised away.
        // SAFETY: i < buf.len().
        unsafe { std::ptr::write_volatile(buf.as_mut_ptr().add(i), 1) };
    }
    std::hint::black_box(&buf);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locking_needs_root_or_an_unlimited_limit() {
        assert!(may_lock_memory(0, 65536).is_ok());
        assert!(may_lock_memory(1000, libc::RLIM_INFINITY).is_ok());
        let e = may_lock_memory(1000, 8 << 20).unwrap_err();
        assert!(e.to_string().contains("LimitMEMLOCK"), "{e}");
    }

    #[test]
    fn the_writer_is_raised_only_after_the_loop() {
        let refused = || Err(io::Error::from_raw_os_error(libc::EPERM));
        let asked = std::cell::Cell::new(0);
        let writer = |p| {
            asked.set(p);
            Ok(())
        };
        // The loop refused (its priority above RLIMIT_RTPRIO, say): the
        // writer, though it might be allowed, stays normal.
        let s = raise_loop_then_writer(35, 25, |_| refused(), writer);
        assert!(matches!(s.loop_thread, Some(Err(_))) && s.writer.is_none());
        assert_eq!(asked.get(), 0);
        let s = raise_loop_then_writer(35, 25, |_| Ok(()), writer);
        assert!(matches!(
            (s.loop_thread, s.writer),
            (Some(Ok(())), Some(Ok(())))
        ));
        assert_eq!(asked.get(), 25);
        let s = raise_loop_then_writer(35, 25, |_| Ok(()), |_| refused());
        assert!(matches!(s.writer, Some(Err(_))));
        // Not asked for.
        let s = raise_loop_then_writer(35, 0, |_| Ok(()), |_| refused());
        assert!(s.writer.is_none());
        let s = raise_loop_then_writer(0, 25, |_| refused(), |_| refused());
        assert!(s.loop_thread.is_none() && s.writer.is_none());
    }

    #[test]
    fn pinning_to_an_allowed_cpu_works_and_to_a_missing_one_fails() {
        std::thread::spawn(|| {
            pin_current_thread(&[0]).unwrap();
            assert!(pin_current_thread(&[1000]).is_err());
            pin_current_thread(&[]).unwrap();
        })
        .join()
        .unwrap();
    }
}
