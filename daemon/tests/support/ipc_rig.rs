//! The daemon's IPC pieces as `main` builds them, in an isolated iceoryx2
//! namespace, and a raw client on them: shared by the loop tests
//! (`loop_allocations.rs`, `long_run.rs`, `drift_replan.rs`) that drive
//! `Runtime` with the mock clock; [`gait_loop`] is the real gait controller
//! in that loop.

#![allow(dead_code)]

use gaitd::config::DaemonConfig;
use gaitd::io::ipc::{self, Ipc};
use gaitd::io::outbox;
use gaitd::sys::shared::Shared;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use shm_schema::{Answer, Command, Event, ServiceNames, Status};
use std::sync::Arc;

/// An isolated iceoryx2 namespace for this test, removed afterwards.
pub struct Namespace {
    /// The daemon config pointing at this namespace.
    pub cfg: DaemonConfig,
    root: std::path::PathBuf,
    file_prefix: String,
}

impl Namespace {
    /// A fresh namespace tagged `tag` (unique per process).
    pub fn new(tag: &str) -> Self {
        let id = format!("{}-{tag}", std::process::id());
        let root = std::env::temp_dir().join(format!("gaitd-alloc-{id}"));
        let mut cfg = DaemonConfig::default();
        cfg.ipc.service_prefix = format!("alloc-{id}");
        cfg.ipc.root_path = format!("{}/", root.display());
        cfg.ipc.file_prefix = format!("ga{}{tag}_", std::process::id());
        cfg.rt.lock_memory = false;
        cfg.rt.fifo_priority = 0;
        let file_prefix = cfg.ipc.file_prefix.clone();
        Self {
            cfg,
            root,
            file_prefix,
        }
    }
}

impl Drop for Namespace {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.root);
        if let Ok(dir) = std::fs::read_dir("/dev/shm") {
            for e in dir.flatten() {
                if e.file_name()
                    .to_string_lossy()
                    .starts_with(&self.file_prefix)
                {
                    let _ = std::fs::remove_file(e.path());
                }
            }
        }
    }
}

/// The test's client: raw iceoryx2 ports on the daemon's services.
pub struct TestClient {
    commands: Publisher<Ipc, Command, ()>,
    answers: Subscriber<Ipc, Answer, ()>,
    status: Subscriber<Ipc, Status, ()>,
    events: Subscriber<Ipc, Event, ()>,
    listener: Listener<Ipc>,
    _node: Node<Ipc>,
}

impl TestClient {
    /// Opens the services named `names`.
    pub fn open(config: &iceoryx2::config::Config, names: &ServiceNames) -> Self {
        let node = NodeBuilder::new().config(config).create::<Ipc>().unwrap();
        let sn = |s: &str| ServiceName::new(s).unwrap();
        let commands = node
            .service_builder(&sn(&names.commands))
            .publish_subscribe::<Command>()
            .open()
            .unwrap()
            .publisher_builder()
            .create()
            .unwrap();
        let answers = node
            .service_builder(&sn(&names.answers))
            .publish_subscribe::<Answer>()
            .open()
            .unwrap()
            .subscriber_builder()
            .create()
            .unwrap();
        let status = node
            .service_builder(&sn(&names.status))
            .publish_subscribe::<Status>()
            .open()
            .unwrap()
            .subscriber_builder()
            .create()
            .unwrap();
        let events = node
            .service_builder(&sn(&names.events))
            .publish_subscribe::<Event>()
            .open()
            .unwrap()
            .subscriber_builder()
            .create()
            .unwrap();
        let listener = node
            .service_builder(&sn(&names.notify))
            .event()
            .open()
            .unwrap()
            .listener_builder()
            .create()
            .unwrap();
        Self {
            commands,
            answers,
            status,
            events,
            listener,
            _node: node,
        }
    }

    /// Publishes a command (the daemon must be subscribed).
    pub fn send(&self, c: Command) {
        let n = self
            .commands
            .loan_uninit()
            .unwrap()
            .write_payload(c)
            .send()
            .unwrap();
        assert_eq!(n, 1, "the daemon subscribes to commands");
    }

    /// Waits (bounded) for the writer thread to publish the next answer.
    pub fn wait_answer(&self) -> Answer {
        let t0 = std::time::Instant::now();
        loop {
            if let Some(s) = self.answers.receive().unwrap() {
                let a = *s.payload();
                assert!(a.verdict().is_ok(), "answer clients reject: {a:?}");
                return a;
            }
            assert!(
                t0.elapsed() < std::time::Duration::from_secs(10),
                "no answer"
            );
            std::thread::yield_now();
        }
    }

    /// Drains status, events and notifications; returns (statuses, events).
    /// Each one must pass the check every client makes (a sample that
    /// fails it is dropped by clients, so the daemon must never send one).
    pub fn drain(&self) -> (Vec<Status>, Vec<Event>) {
        let mut st = Vec::new();
        while let Some(s) = self.status.receive().unwrap() {
            let s = *s.payload();
            assert_eq!(s.check(), Ok(()), "status clients reject: {s:?}");
            st.push(s);
        }
        let mut ev = Vec::new();
        while let Some(s) = self.events.receive().unwrap() {
            let e = *s.payload();
            assert_eq!(e.check(), Ok(()), "event clients reject: {e:?}");
            ev.push(e);
        }
        self.listener.try_wait(|_| {}).unwrap();
        (st, ev)
    }
}

/// The daemon's IPC pieces, as `main` builds them.
pub struct Daemon {
    /// The loop's command subscriber.
    pub commands: Subscriber<Ipc, Command, ()>,
    pub outbox: outbox::Outbox,
    pub writer: outbox::Writer,
    pub client: TestClient,
    pub shared: Arc<Shared>,
    /// The loop's plant ports (with `[plant] kind = "shm"`).
    pub plant: Option<ipc::PlantInPorts>,
    _plant_services: Option<ipc::PlantInServices>,
    _commands_service:
        iceoryx2::service::port_factory::publish_subscribe::PortFactory<Ipc, Command, ()>,
    _node: Node<Ipc>,
}

/// The daemon's ports and writer thread in `ns`, with a client connected.
pub fn daemon(ns: &Namespace) -> Daemon {
    let (ice, settings) = ipc::resolve(&ns.cfg.ipc).unwrap();
    let node = ipc::create_node("gaitd", &ice).unwrap();
    let services = ipc::create_services(&node, &ns.cfg, &settings.service_prefix).unwrap();
    let commands = services.command_subscriber(8).unwrap();
    let ipc::DaemonServices {
        commands: commands_service,
        out,
        plant_in,
        names,
        ..
    } = services;
    let client = TestClient::open(&ice, &names);
    let shared = Arc::new(Shared::default());
    // The loop runs on the mock clock: the writer must be woken by it.
    let settings = outbox::WriterSettings {
        status_notify_every: 1,
        wake: outbox::WriterWake::Unpark,
        period: ns.cfg.period_ns(),
        spin: 0,
        cpus: Vec::new(),
        doorbells: Vec::new(),
    };
    let names_for_plant = names.clone();
    let (outbox, writer) = outbox::spawn(out, names, settings, shared.clone()).unwrap();
    let plant = plant_in.map(|p| p.ports(&names_for_plant).unwrap());
    Daemon {
        commands,
        outbox,
        writer,
        client,
        shared,
        plant,
        _plant_services: None,
        _commands_service: commands_service,
        _node: node,
    }
}

/// Waits (bounded) until the writer thread has published all but a few of
/// the messages the loop queued: a loop on the mock clock runs far faster
/// than real time, and when the writer falls behind by the ring's capacity
/// the loop drops messages (counted), so tests that count events let it
/// catch up.
pub fn let_writer_catch_up(shared: &Shared) {
    use std::sync::atomic::Ordering;
    let t0 = std::time::Instant::now();
    while shared.queued.load(Ordering::Acquire) > shared.published.load(Ordering::Acquire) + 128 {
        assert!(
            t0.elapsed() < std::time::Duration::from_secs(10),
            "writer stuck"
        );
        std::thread::yield_now();
    }
}

/// The real gait controller (planner thread, executor, kinematic hand) in
/// the real loop (`Runtime`) on the mock clock, with a client connected.
pub struct GaitLoop {
    pub rt: gaitd::realtime::runtime::Runtime<
        gaitd::control::gait_controller::GaitController,
        gaitd::sys::clock::MockClock,
    >,
    pub clock: gaitd::sys::clock::MockClock,
    pub client: TestClient,
    pub shared: Arc<Shared>,
    writer: outbox::Writer,
    planner: gaitd::control::plan_thread::PlannerThread,
    _commands_service:
        iceoryx2::service::port_factory::publish_subscribe::PortFactory<Ipc, Command, ()>,
    _node: Node<Ipc>,
}

/// [`GaitLoop`] in `ns` as daemon `instance`; `setup` adjusts the
/// controller before the loop takes it (e.g. a trace recorder).
pub fn gait_loop(
    ns: &Namespace,
    instance: u64,
    setup: impl FnOnce(&mut gaitd::control::gait_controller::GaitController),
) -> GaitLoop {
    use gaitd::control::gait_controller::GaitPlanner;
    let planner = gait::planner::Planner::new(&ns.cfg.hand()).unwrap();
    gait_loop_with(ns, instance, GaitPlanner::new(planner, None), setup)
}

/// [`gait_loop`] with another planner on the planner thread (e.g. one that
/// fails in a chosen way).
pub fn gait_loop_with<P>(
    ns: &Namespace,
    instance: u64,
    planner: P,
    setup: impl FnOnce(&mut gaitd::control::gait_controller::GaitController),
) -> GaitLoop
where
    P: gaitd::control::plan_thread::BackgroundPlanner<
            Request = gaitd::control::gait_controller::GoalPlanRequest,
            Plan = gait::planner::Plan,
            Error = gait::planner::PlanError,
        >,
{
    gait_loop_on(ns, instance, planner, None, setup)
}

/// The shipped TriFingerPro (`deploy/hands/trifingerpro/`) on a
/// joint-level external plant (`[plant] kind = "shm"` in `ns`), planned
/// by the chain planner, from the shipped start grasp.
pub fn chain_gait_loop(ns: &Namespace, instance: u64) -> GaitLoop {
    use gaitd::control::gait_controller::GaitPlanner;
    let (model, start) = trifingerpro(ns);
    let chain = (model.hand().clone(), start, *model.config());
    let planner = gait::planner::chains::planner::ChainPlanner::new(model);
    gait_loop_on(
        ns,
        instance,
        GaitPlanner::new(planner, None),
        Some(chain),
        |_| {},
    )
}

/// The shipped TriFingerPro's planning model (with `ns`'s settings) and
/// its shipped start grasp.
pub fn trifingerpro(ns: &Namespace) -> (gait::planner::chains::model::ChainModel, gait::HandState) {
    let d = kinematics::HandDescription::parse(
        include_str!("../../../deploy/hands/trifingerpro/trifingerpro.urdf"),
        include_str!("../../../deploy/hands/trifingerpro/hand.toml"),
    )
    .unwrap();
    let hand = gait::planner::chains::ChainHand::new(&d, ns.cfg.hand.grasp_limits()).unwrap();
    let model = gait::planner::chains::model::ChainModel::new(hand, &ns.cfg.hand());
    let normals = [
        [-0.07, 0.07, 1.0],
        [0.55, -0.57, -0.61],
        [-0.64, 0.66, 0.40],
    ];
    let start = model.hand().grasp(model.config(), &normals);
    (model, start)
}

fn gait_loop_on<P>(
    ns: &Namespace,
    instance: u64,
    planner: P,
    chains: Option<(
        gait::planner::chains::ChainHand,
        gait::HandState,
        gait::HandConfig,
    )>,
    setup: impl FnOnce(&mut gaitd::control::gait_controller::GaitController),
) -> GaitLoop
where
    P: gaitd::control::plan_thread::BackgroundPlanner<
            Request = gaitd::control::gait_controller::GoalPlanRequest,
            Plan = gait::planner::Plan,
            Error = gait::planner::PlanError,
        >,
{
    use gaitd::control::gait_controller::GaitController;
    let Daemon {
        commands,
        outbox,
        writer,
        client,
        shared,
        plant,
        _commands_service,
        _node,
        ..
    } = daemon(ns);
    let (link, planner) = gaitd::control::plan_thread::spawn(planner, 4, || {}).unwrap();
    let mut controller = match (&plant, chains) {
        (None, _) => GaitController::new(&ns.cfg.hand(), 1e-3, link).unwrap(),
        (Some(_), chains) => {
            let mut x = gaitd::plant::external::ExternalPlant::new(
                instance,
                ns.cfg.period_ns(),
                &ns.cfg.plant,
            );
            let (hand, start, config) = match chains {
                Some((h, start, config)) => {
                    x = x.with_joints(gaitd::plant::joints::JointLink::new(
                        h.clone(),
                        (&ns.cfg.hand).into(),
                    ));
                    (Some(h), start, config)
                }
                None => {
                    let config = ns.cfg.hand();
                    (None, gait::HandState::paper_start(&config), config)
                }
            };
            GaitController::new_external(&config, (hand, start), 1e-3, link, x).unwrap()
        }
    };
    setup(&mut controller);
    let clock = gaitd::sys::clock::MockClock::new(0);
    let mut rt = gaitd::realtime::runtime::Runtime::new(
        commands,
        outbox,
        controller,
        clock.clone(),
        &ns.cfg,
        instance,
        shared.clone(),
    );
    if let Some(p) = plant {
        rt.set_plant(gaitd::plant::ports::PlantInput::new(p));
    }
    GaitLoop {
        rt,
        clock,
        client,
        shared,
        writer,
        planner,
        _commands_service,
        _node,
    }
}

impl GaitLoop {
    /// One tick: run it, advance mock time by 1 ms, let the writer catch
    /// up, and return what the client received.
    pub fn tick(&mut self) -> (Vec<Status>, Vec<Event>) {
        self.rt.run_once();
        self.clock.advance(1_000_000);
        let_writer_catch_up(&self.shared);
        self.client.drain()
    }

    /// While a plan is being made, lets the planner thread run (mock time
    /// runs on meanwhile, as the daemon's ticks do). Returns whether the
    /// controller is planning.
    pub fn yield_to_planner(&self) -> bool {
        let planning = self.rt.controller().phase() == gait::executor::Mode::Planning;
        if planning {
            std::thread::sleep(std::time::Duration::from_micros(50));
        }
        planning
    }

    /// Stops the loop, then the writer and planner threads.
    pub fn finish(self) {
        let GaitLoop {
            rt,
            writer,
            planner,
            ..
        } = self;
        drop(rt);
        writer.join();
        planner.join();
    }
}

/// A plant in the test process for a daemon with `[plant] kind = "shm"`:
/// the kinematic hand following every command exactly, over the plant
/// services (raw iceoryx2 ports), numbering its measurements and echoing
/// the command it applied.
pub struct RigPlant {
    commands: Subscriber<Ipc, shm_schema::PlantCommand, ()>,
    measurements: Publisher<Ipc, shm_schema::PlantMeasurement, ()>,
    measured: iceoryx2::port::notifier::Notifier<Ipc>,
    commanded: Listener<Ipc>,
    hand: gait::sim::KinematicHand,
    /// A joint-level chain hand: each finger's joints (the fingertip hand
    /// then holds only the object and the contacts).
    joints: Option<[[f64; 3]; 3]>,
    seq: u64,
    time_ns: u64,
    last: Option<shm_schema::PlantCommand>,
    _node: Node<Ipc>,
}

impl RigPlant {
    /// Opens the plant services of the daemon in `ns`, at the paper start.
    pub fn open(ns: &Namespace) -> Self {
        let (ice, settings) = ipc::resolve(&ns.cfg.ipc).unwrap();
        let names = ServiceNames::new(&settings.service_prefix);
        let node = NodeBuilder::new().config(&ice).create::<Ipc>().unwrap();
        let sn = |s: &str| ServiceName::new(s).unwrap();
        let commands = node
            .service_builder(&sn(&names.plant_command))
            .publish_subscribe::<shm_schema::PlantCommand>()
            .open()
            .unwrap()
            .subscriber_builder()
            .buffer_size(2)
            .create()
            .unwrap();
        let measurements = node
            .service_builder(&sn(&names.plant_measurement))
            .publish_subscribe::<shm_schema::PlantMeasurement>()
            .open()
            .unwrap()
            .publisher_builder()
            .create()
            .unwrap();
        let measured = node
            .service_builder(&sn(&names.plant_measured))
            .event()
            .open()
            .unwrap()
            .notifier_builder()
            .create()
            .unwrap();
        let commanded = node
            .service_builder(&sn(&names.plant_commanded))
            .event()
            .open()
            .unwrap()
            .listener_builder()
            .create()
            .unwrap();
        let start = gait::HandState::paper_start(&ns.cfg.hand());
        Self {
            commands,
            measurements,
            measured,
            commanded,
            hand: gait::sim::KinematicHand::new(start, 1e-3),
            joints: None,
            seq: 0,
            time_ns: 0,
            last: None,
            _node: node,
        }
    }

    /// A joint-level plant of the chain hand `hand` in the grasp `start`,
    /// each finger on the branch the daemon picks: it takes each command's
    /// joints as its own and measures joints.
    pub fn open_joints(
        ns: &Namespace,
        hand: &gait::planner::chains::ChainHand,
        start: gait::HandState,
    ) -> Self {
        let mut p = Self::open(ns);
        p.hand = gait::sim::KinematicHand::new(start, 1e-3);
        p.joints = Some(std::array::from_fn(|k| {
            hand.joints(k, &start.fingers[k].center, None)
                .expect("the start grasp is reached")
                .into()
        }));
        p
    }

    /// Publishes the next measurement of the hand's state (and notifies).
    pub fn publish(&mut self) {
        use shm_schema::{PlantMeasurement, measurement_valid, plant_state};
        self.seq += 1;
        self.time_ns += 1_000_000;
        let s = *self.hand.state();
        let q = |q: &nalgebra::UnitQuaternion<f64>| [q.w, q.i, q.j, q.k];
        let mut m = PlantMeasurement {
            session: self.last.map_or(0, |c| c.session),
            seq: self.seq,
            applied: self.last.map_or(0, |c| c.seq),
            time_ns: self.time_ns,
            valid: measurement_valid::REQUIRED,
            state: plant_state::SIMULATED,
            object_q: q(&s.object),
            ..PlantMeasurement::default()
        };
        for (w, f) in m.fingers.iter_mut().zip(&s.fingers) {
            w.position = f.center.into();
            w.orientation = q(&f.orientation);
            w.roll = f.roll;
            w.contact = u32::from(f.mode == gait::FingerMode::Grasping);
        }
        if let Some(joints) = &self.joints {
            m.valid = measurement_valid::REQUIRED_JOINTS;
            for (w, q) in m.fingers.iter_mut().zip(joints) {
                w.joint_count = 3;
                w.joint_position[..3].copy_from_slice(q);
            }
        }
        self.measurements
            .loan_uninit()
            .unwrap()
            .write_payload(m)
            .send()
            .unwrap();
        self.measured.notify().unwrap();
    }

    /// Takes the newest command, waiting (bounded, wall clock) for one that
    /// answers our last measurement; applies it. Returns false on timeout.
    pub fn follow(&mut self, timeout: std::time::Duration) -> bool {
        let t0 = std::time::Instant::now();
        loop {
            let mut newest = None;
            while let Some(s) = self.commands.receive().unwrap() {
                newest = Some(*s.payload());
            }
            if let Some(c) = newest
                && c.answers == self.seq
            {
                self.apply(&c);
                return true;
            }
            if t0.elapsed() > timeout {
                return false;
            }
            let _ = self
                .commanded
                .timed_wait(|_| {}, std::time::Duration::from_millis(5));
        }
    }

    fn apply(&mut self, c: &shm_schema::PlantCommand) {
        use gait::sim::Plant;
        use nalgebra::{Quaternion, UnitQuaternion, Vector3};
        let quat =
            |q: [f64; 4]| UnitQuaternion::new_normalize(Quaternion::new(q[0], q[1], q[2], q[3]));
        self.last = Some(*c);
        if c.flags & shm_schema::command_flags::ENABLE == 0 {
            return;
        }
        if let Some(joints) = self.joints.as_mut() {
            for (q, cf) in joints.iter_mut().zip(&c.fingers) {
                q.copy_from_slice(&cf.joint_position[..3]);
            }
        }
        let mut state = *self.hand.state();
        state.object = quat(c.object_q);
        for (f, cf) in state.fingers.iter_mut().zip(&c.fingers) {
            f.center = Vector3::from(cf.position);
            f.orientation = quat(cf.orientation);
            f.roll = cf.roll;
            f.mode = if cf.mode == shm_schema::PlantFingerMode::Grasping.code() {
                gait::FingerMode::Grasping
            } else {
                gait::FingerMode::Free
            };
        }
        self.hand.write(&gait::planner::Setpoint {
            state,
            object_rate: Vector3::from(c.object_omega),
            finger_velocity: c.fingers.map(|f| Vector3::from(f.velocity)),
            finger_rate: c.fingers.map(|f| Vector3::from(f.angular_velocity)),
            estimate_epoch: 0,
        });
    }

    /// The hand's true state.
    pub fn state(&self) -> &gait::HandState {
        self.hand.state()
    }
}
