//! Attach a hand or a simulator to gaitd (shm_schema `PLANT-GUIDE.md`):
//! implement [`PlantModel`] and run it with [`PlantHost`], which speaks the
//! plant protocol — numbered measurements that echo the command applied,
//! lockstep or real time, every command checked before the model sees it,
//! the grasp held while no (valid) command comes.
//!
//! ```no_run
//! use gaitd_client::plant::{PlantHost, PlantModel, Pacing};
//! use gaitd_client::ConnectOptions;
//! use gaitd_client::shm_schema::{PlantCommand, PlantMeasurement};
//! # struct MyHand;
//! # impl PlantModel for MyHand {
//! #     fn apply(&mut self, _c: &PlantCommand) {}
//! #     fn step(&mut self, _dt: f64) {}
//! #     fn measure(&mut self, _m: &mut PlantMeasurement) {}
//! # }
//! let mut host = PlantHost::open(&ConnectOptions::new())?;
//! let stop = std::sync::atomic::AtomicBool::new(false);
//! let report = host.run(&mut MyHand, Pacing::Lockstep, 1_000_000, &stop)?;
//! println!("{} steps", report.steps);
//! # Ok::<(), gaitd_client::Error>(())
//! ```

use crate::connection::{Attempt, Ipc, ipc_err, open_err, open_event, open_pubsub, wait_for_dir};
use crate::error::{Error, Result};
use crate::options::ConnectOptions;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use shm_schema::{PlantCommand, PlantMeasurement, ServiceNames, command_flags};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Notification id on the plant wake-up services.
const PLANT_EVENT_ID: usize = 1;

/// A hand or simulator: what [`PlantHost`] drives.
pub trait PlantModel {
    /// Takes a checked command (`flags` has ENABLE): follow its setpoints.
    fn apply(&mut self, command: &PlantCommand);
    /// Advances by `dt` seconds (a simulator steps its physics; a real
    /// hand's clock runs by itself, so it does nothing).
    fn step(&mut self, dt: f64);
    /// Fills the physical fields of a measurement: object, fingers, `valid`
    /// bits, `state` bits and `fault` (the host sets the numbering).
    fn measure(&mut self, m: &mut PlantMeasurement);
}

/// How the plant is paced (PLANT-GUIDE.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pacing {
    /// Measurement k, then wait for the command answering k, then step.
    Lockstep,
    /// Step on the wall clock every period, with the newest command.
    Realtime,
}

/// Why a command was not applied.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refused {
    /// A code or flag the schema does not define.
    Codes,
    /// A non-finite number.
    NonFinite,
    /// A quaternion that is not of unit norm.
    NonUnit,
}

/// What a run did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RunReport {
    /// Plant steps taken.
    pub steps: u64,
    /// Commands applied.
    pub applied: u64,
    /// Commands refused ([`PlantHost::check`]).
    pub refused: u64,
    /// Simulated seconds.
    pub sim_seconds: f64,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
}

/// The plant's side of the plant services (module docs).
#[derive(Debug)]
pub struct PlantHost {
    commands: Subscriber<Ipc, PlantCommand, ()>,
    measurements: Publisher<Ipc, PlantMeasurement, ()>,
    commanded: Listener<Ipc>,
    measured: Notifier<Ipc>,
    seq: u64,
    time_ns: u64,
    /// The last command applied.
    last: Option<PlantCommand>,
    // Dropped last: the ports above first.
    _node: Node<Ipc>,
}

fn finite(xs: &[f64]) -> bool {
    xs.iter().all(|x| x.is_finite())
}

fn unit(q: &[f64; 4]) -> bool {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    (n - 1.0).abs() <= 1e-3
}

impl PlantHost {
    /// Opens the plant services of the daemon `opts` names, waiting up to
    /// its timeout for them (and for a dead predecessor's publisher slot).
    pub fn open(opts: &ConnectOptions) -> Result<Self> {
        let (config, settings) = opts.resolve()?;
        let deadline = Instant::now() + opts.timeout;
        let names = ServiceNames::new(&settings.service_prefix);
        let no_daemon = || Error::NoDaemon {
            prefix: settings.service_prefix.clone(),
            root: settings.root_path.clone(),
            waited: opts.timeout,
        };
        if !std::path::Path::new(&settings.root_path).is_dir() {
            wait_for_dir(&settings.root_path, deadline).ok_or_else(no_daemon)?;
        }
        let node = NodeBuilder::new()
            .name(&NodeName::new("gaitd-plant").map_err(|e| ipc_err("node name")(&e))?)
            .config(&config)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<Ipc>()
            .map_err(|e| ipc_err("node")(&e))?;
        loop {
            match Self::try_ports(&node, &names) {
                Ok(Attempt::Done((commands, measurements, commanded, measured))) => {
                    return Ok(Self {
                        commands,
                        measurements,
                        commanded,
                        measured,
                        seq: 0,
                        time_ns: 0,
                        last: None,
                        _node: node,
                    });
                }
                // Not there yet, or a dead plant still holds the slot
                // until the daemon's housekeeping cleans it up.
                Ok(Attempt::Missing) | Err(Error::Open { .. }) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(20));
                }
                Ok(Attempt::Missing) => {
                    return Err(Error::NoDaemon {
                        prefix: format!(
                            "{} (plant services: is [plant] kind = \"shm\"?)",
                            settings.service_prefix
                        ),
                        root: settings.root_path.clone(),
                        waited: opts.timeout,
                    });
                }
                Err(e) => return Err(e),
            }
        }
    }

    #[allow(clippy::type_complexity)]
    fn try_ports(
        node: &Node<Ipc>,
        names: &ServiceNames,
    ) -> Result<
        Attempt<(
            Subscriber<Ipc, PlantCommand, ()>,
            Publisher<Ipc, PlantMeasurement, ()>,
            Listener<Ipc>,
            Notifier<Ipc>,
        )>,
    > {
        // Which schema the daemon speaks, before a type name says "incompatible".
        crate::connection::check_version(node, &names.version)?;
        let Attempt::Done(c) = open_pubsub::<PlantCommand>(node, &names.plant_command)? else {
            return Ok(Attempt::Missing);
        };
        let Attempt::Done(m) = open_pubsub::<PlantMeasurement>(node, &names.plant_measurement)?
        else {
            return Ok(Attempt::Missing);
        };
        let Attempt::Done(cd) = open_event(node, &names.plant_commanded)? else {
            return Ok(Attempt::Missing);
        };
        let Attempt::Done(md) = open_event(node, &names.plant_measured)? else {
            return Ok(Attempt::Missing);
        };
        Ok(Attempt::Done((
            c.subscriber_builder()
                .buffer_size(2)
                .create()
                .map_err(|e| open_err(&names.plant_command, e))?,
            m.publisher_builder()
                .max_loaned_samples(1)
                .create()
                .map_err(|e| open_err(&names.plant_measurement, e))?,
            cd.listener_builder()
                .create()
                .map_err(|e| open_err(&names.plant_commanded, e))?,
            md.notifier_builder()
                .create()
                .map_err(|e| open_err(&names.plant_measured, e))?,
        )))
    }

    /// Whether a command may be applied: known codes and flags, finite
    /// numbers, unit quaternions (a plant never trusts the daemon's bytes).
    pub fn check(c: &PlantCommand) -> std::result::Result<(), Refused> {
        c.check().map_err(|_| Refused::Codes)?;
        let mut ok = finite(&c.object_q) && finite(&c.object_omega);
        for f in &c.fingers {
            ok &= finite(&f.position)
                && finite(&f.orientation)
                && finite(&f.velocity)
                && finite(&f.angular_velocity)
                && finite(&f.acceleration)
                && f.roll.is_finite()
                && f.grip_force.is_finite();
        }
        if !ok {
            return Err(Refused::NonFinite);
        }
        if !unit(&c.object_q) || c.fingers.iter().any(|f| !unit(&f.orientation)) {
            return Err(Refused::NonUnit);
        }
        Ok(())
    }

    /// The newest command received since the last call, if any.
    fn newest(&mut self) -> Result<Option<PlantCommand>> {
        let mut newest = None;
        while let Some(s) = self
            .commands
            .receive()
            .map_err(|e| ipc_err("receive a plant command")(&e))?
        {
            newest = Some(*s.payload());
        }
        Ok(newest)
    }

    /// Applies `c` if it passes [`PlantHost::check`] and enables the plant.
    fn take(&mut self, model: &mut dyn PlantModel, c: &PlantCommand, r: &mut RunReport) {
        match Self::check(c) {
            Ok(()) => {
                if c.flags & command_flags::ENABLE != 0 {
                    model.apply(c);
                }
                self.last = Some(*c);
                r.applied += 1;
            }
            Err(_) => r.refused += 1,
        }
    }

    /// Measures, numbers and publishes one measurement, then notifies.
    fn publish(&mut self, model: &mut dyn PlantModel) -> Result<()> {
        self.seq += 1;
        let mut m = PlantMeasurement::default();
        model.measure(&mut m);
        m.seq = self.seq;
        m.time_ns = self.time_ns;
        m.session = self.last.map_or(0, |c| c.session);
        m.applied = self.last.map_or(0, |c| c.seq);
        self.send_raw(&m)
    }

    /// Runs `model` until `stop` (PLANT-GUIDE.md): `period_ns` is the step
    /// before the first command tells the daemon's.
    pub fn run(
        &mut self,
        model: &mut dyn PlantModel,
        timing: Pacing,
        period_ns: u64,
        stop: &AtomicBool,
    ) -> Result<RunReport> {
        let mut r = RunReport::default();
        let t0 = Instant::now();
        let mut period = period_ns.max(1);
        self.publish(model)?;
        let mut next = Instant::now() + Duration::from_nanos(period);
        while !stop.load(Ordering::Acquire) {
            match timing {
                Pacing::Lockstep => {
                    // Wait for the command answering our last measurement;
                    // meanwhile republish it now and then (the daemon may
                    // have restarted) and keep the grasp.
                    let interrupted = self.wait_commanded(Duration::from_millis(100))?;
                    let Some(c) = self.newest()? else {
                        // (A signal is no silence of the daemon's.)
                        if !interrupted {
                            self.republish(model)?;
                        }
                        continue;
                    };
                    if c.answers != self.seq {
                        continue;
                    }
                    self.take(model, &c, &mut r);
                    period = if c.period_ns > 0 { c.period_ns } else { period };
                }
                Pacing::Realtime => {
                    let now = Instant::now();
                    if now < next {
                        std::thread::sleep(next - now);
                    }
                    next += Duration::from_nanos(period);
                    if let Some(c) = self.newest()? {
                        self.take(model, &c, &mut r);
                        period = if c.period_ns > 0 { c.period_ns } else { period };
                    }
                }
            }
            model.step(period as f64 * 1e-9);
            self.time_ns += period;
            r.steps += 1;
            self.publish(model)?;
        }
        r.sim_seconds = self.time_ns as f64 * 1e-9;
        r.wall_seconds = t0.elapsed().as_secs_f64();
        Ok(r)
    }

    /// Publishes `m` exactly as given (no numbering, no echo) and notifies:
    /// for plants that number their own measurements (and for test
    /// fixtures that must lie).
    pub fn send_raw(&mut self, m: &PlantMeasurement) -> Result<()> {
        let sample = self
            .measurements
            .loan_uninit()
            .map_err(|e| ipc_err("loan a measurement")(&e))?;
        sample
            .write_payload(*m)
            .send()
            .map_err(|e| ipc_err("send a measurement")(&e))?;
        self.measured
            .notify_with_custom_event_id(EventId::new(PLANT_EVENT_ID))
            .map_err(|e| ipc_err("notify a measurement")(&e))?;
        Ok(())
    }

    /// The newest command received since the last call, without waiting.
    pub fn try_command(&mut self) -> Result<Option<PlantCommand>> {
        self.newest()
    }

    /// The newest command received, waiting up to `timeout` for one.
    pub fn next_command(&mut self, timeout: Duration) -> Result<Option<PlantCommand>> {
        if let Some(c) = self.newest()? {
            return Ok(Some(c));
        }
        self.wait_commanded(timeout)?;
        self.newest()
    }

    /// Waits up to `timeout` for the daemon's "commanded" wake-up. A signal
    /// that interrupts the wait (one the process handles) ends it early,
    /// like a wake-up: the caller looks for a command either way. Returns
    /// whether a signal ended it.
    fn wait_commanded(&self, timeout: Duration) -> Result<bool> {
        match self.commanded.timed_wait(|_| {}, timeout) {
            Ok(_) => Ok(false),
            Err(ListenerWaitError::InterruptSignal) => Ok(true),
            Err(e) => Err(ipc_err("wait for a command")(&e)),
        }
    }

    /// Lockstep with no command for a while: publishes the last measurement
    /// again (same sequence number and time), so a restarted daemon learns
    /// the state.
    fn republish(&mut self, model: &mut dyn PlantModel) -> Result<()> {
        self.seq -= 1;
        self.publish(model)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_schema::PlantFingerMode;

    fn good() -> PlantCommand {
        let mut c = PlantCommand {
            flags: command_flags::ENABLE,
            object_q: [1.0, 0.0, 0.0, 0.0],
            ..PlantCommand::default()
        };
        for f in &mut c.fingers {
            f.mode = PlantFingerMode::Grasping.code();
            f.orientation = [1.0, 0.0, 0.0, 0.0];
        }
        c
    }

    #[test]
    fn commands_are_checked_before_a_model_sees_them() {
        assert_eq!(PlantHost::check(&good()), Ok(()));
        let mut c = good();
        c.fingers[1].velocity[0] = f64::NAN;
        assert_eq!(PlantHost::check(&c), Err(Refused::NonFinite));
        let mut c = good();
        c.object_q = [2.0, 0.0, 0.0, 0.0];
        assert_eq!(PlantHost::check(&c), Err(Refused::NonUnit));
        let mut c = good();
        c.fingers[2].mode = 9;
        assert_eq!(PlantHost::check(&c), Err(Refused::Codes));
        let mut c = good();
        c.flags = 1 << 7;
        assert_eq!(PlantHost::check(&c), Err(Refused::Codes));
    }
}
