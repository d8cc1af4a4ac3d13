//! The hand the daemon runs, as its configuration describes it: the
//! paper's free fingertips, or a chain hand read from its description
//! (URDF + hand section, SPEC §14) — with the configuration the planner,
//! executor and trace use, and the grasp the embedded hand starts in.

use std::path::{Path, PathBuf};

use gait::planner::PlanError;
use gait::planner::chains::model::ChainModel;
use gait::planner::chains::planner::ChainPlanner;
use gait::planner::chains::{ChainHand, ChainHandError};
use gait::{HandConfig, HandState};

use crate::config::DaemonConfig;

/// Why the configured hand cannot be set up; each names the file or key.
#[derive(Debug, thiserror::Error)]
pub enum HandSetupError {
    /// The description's files could not be read, or are not a hand.
    #[error("hand description {0}")]
    Load(#[from] kinematics::LoadError),
    /// The described hand is not one gaitd plans for.
    #[error("hand description {path}: {source}")]
    Hand {
        /// The hand section file.
        path: PathBuf,
        /// What is wrong.
        source: Box<ChainHandError>,
    },
    /// The configured start grasp is not one the hand can start in.
    #[error("hand.start_normals: the start grasp is not valid: {0}")]
    Start(PlanError),
}

/// The hand the daemon runs (module docs).
#[derive(Debug, Clone)]
pub struct HandSetup {
    /// The configuration planning and checking use: the file's, with a
    /// chain hand's geometry, friction, object and gravity in place of
    /// `[model]`'s and `[load]`'s.
    pub config: HandConfig,
    /// A chain hand's planner model (`None`: free fingertips).
    pub chains: Option<ChainModel>,
    /// Where the embedded hand starts: the paper's start grasp, or the
    /// configured one of a chain hand.
    pub start: HandState,
}

impl HandSetup {
    /// Reads and checks the hand `cfg` configures (a chain hand's start
    /// grasp as the chain planner would check a plan's start).
    pub fn load(cfg: &DaemonConfig) -> Result<Self, HandSetupError> {
        let config = cfg.hand();
        if !cfg.hand.chains() {
            return Ok(Self {
                config,
                chains: None,
                start: HandState::paper_start(&config),
            });
        }
        let section_path = resolve(&cfg.dir, &cfg.hand.description);
        let description =
            kinematics::HandDescription::load(&section_path, |p| std::fs::read_to_string(p))?;
        let hand = ChainHand::new(&description, cfg.hand.grasp_limits()).map_err(|source| {
            HandSetupError::Hand {
                path: section_path.clone(),
                source: Box::new(source),
            }
        })?;
        let model = ChainModel::new(hand, &config);
        let start = model.hand().grasp(model.config(), &cfg.hand.start_normals);
        ChainPlanner::new(model.clone())
            .check_start(&start)
            .map_err(HandSetupError::Start)?;
        Ok(Self {
            config: *model.config(),
            chains: Some(model),
            start,
        })
    }
}

/// `path` as given when absolute, else from `dir`.
fn resolve(dir: &Path, path: &str) -> PathBuf {
    let p = Path::new(path);
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        dir.join(p)
    }
}
