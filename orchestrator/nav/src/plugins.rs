//! Which implementation runs behind each seam, chosen by name (as Nav2 chooses its planner
//! and controller plugins): in [`NavConfig`](super::NavConfig)'s `[plugins]` table, or by a
//! scenario's `[nav]` keys `planner` and `controller`. A new planner or controller is a
//! variant, its name and its constructor here.

use super::astar::{AStar, PlannerConfig};
use super::controller::Controller;
use super::dwa::{ControllerConfig, Dwa};
use super::global_planner::GlobalPlanner;
use super::straight_line::StraightLine;
use serde::{Deserialize, Serialize};
use std::fmt;

/// The global planner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(try_from = "String", into = "&'static str")]
pub enum PlannerKind {
    /// [`AStar`]: A* on the inflated costmap, shortcut.
    #[default]
    Astar,
    /// [`StraightLine`]: the straight segment, refused when not free (open ground).
    StraightLine,
}

impl PlannerKind {
    pub fn build(self, cfg: &PlannerConfig) -> Box<dyn GlobalPlanner> {
        match self {
            PlannerKind::Astar => Box::new(AStar { cfg: *cfg }),
            PlannerKind::StraightLine => Box::new(StraightLine { cfg: *cfg }),
        }
    }
}

impl Named for PlannerKind {
    const KEY: &'static str = "planner";
    const ALL: &'static [PlannerKind] = &[PlannerKind::Astar, PlannerKind::StraightLine];
    fn name(self) -> &'static str {
        match self {
            PlannerKind::Astar => "astar",
            PlannerKind::StraightLine => "straight_line",
        }
    }
}

/// The controller (local planner).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(try_from = "String", into = "&'static str")]
pub enum ControllerKind {
    /// [`Dwa`]: the holonomic Dynamic Window Approach.
    #[default]
    Dwa,
}

impl ControllerKind {
    pub fn build(self, cfg: &ControllerConfig) -> Box<dyn Controller> {
        match self {
            ControllerKind::Dwa => Box::new(Dwa { cfg: *cfg }),
        }
    }
}

impl Named for ControllerKind {
    const KEY: &'static str = "controller";
    const ALL: &'static [ControllerKind] = &[ControllerKind::Dwa];
    fn name(self) -> &'static str {
        match self {
            ControllerKind::Dwa => "dwa",
        }
    }
}

/// The implementations behind the two seams.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Plugins {
    pub planner: PlannerKind,
    pub controller: ControllerKind,
}

impl Plugins {
    /// The planner and controller named `planner` and `controller` (a scenario's `[nav]` keys).
    pub fn from_names(planner: &str, controller: &str) -> Result<Plugins, UnknownName> {
        Ok(Plugins { planner: by_name(planner)?, controller: by_name(controller)? })
    }
}

/// A name no implementation answers to; says which key and what it may be.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownName {
    pub key: &'static str,
    pub name: String,
    pub allowed: Vec<&'static str>,
}

impl fmt::Display for UnknownName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let allowed: Vec<String> = self.allowed.iter().map(|a| format!("\"{a}\"")).collect();
        write!(f, "{} = \"{}\" is unknown; allowed: {}", self.key, self.name, allowed.join(", "))
    }
}

impl std::error::Error for UnknownName {}

/// A choice among implementations, each with its name.
pub trait Named: Copy + 'static {
    /// The key that names the choice.
    const KEY: &'static str;
    const ALL: &'static [Self];
    fn name(self) -> &'static str;
}

fn by_name<T: Named>(name: &str) -> Result<T, UnknownName> {
    T::ALL.iter().copied().find(|k| k.name() == name).ok_or_else(|| UnknownName {
        key: T::KEY,
        name: name.to_string(),
        allowed: T::ALL.iter().map(|k| k.name()).collect(),
    })
}

impl TryFrom<String> for PlannerKind {
    type Error = UnknownName;
    fn try_from(name: String) -> Result<Self, UnknownName> {
        by_name(&name)
    }
}

impl From<PlannerKind> for &'static str {
    fn from(k: PlannerKind) -> &'static str {
        k.name()
    }
}

impl TryFrom<String> for ControllerKind {
    type Error = UnknownName;
    fn try_from(name: String) -> Result<Self, UnknownName> {
        by_name(&name)
    }
}

impl From<ControllerKind> for &'static str {
    fn from(k: ControllerKind) -> &'static str {
        k.name()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_choose_the_implementations_and_unknown_names_say_what_is_allowed() {
        let p = Plugins::from_names("straight_line", "dwa").unwrap();
        assert_eq!(p, Plugins { planner: PlannerKind::StraightLine, controller: ControllerKind::Dwa });
        assert_eq!(Plugins::from_names("astar", "dwa").unwrap(), Plugins::default());
        let e = Plugins::from_names("a_star", "dwa").unwrap_err();
        assert_eq!(e.to_string(), "planner = \"a_star\" is unknown; allowed: \"astar\", \"straight_line\"");
        let e = Plugins::from_names("astar", "teb").unwrap_err();
        assert_eq!(e.to_string(), "controller = \"teb\" is unknown; allowed: \"dwa\"");
    }

    #[test]
    fn every_name_reads_back_from_toml() {
        for &k in PlannerKind::ALL {
            let p: Plugins = toml::from_str(&format!("planner = \"{}\"", k.name())).unwrap();
            assert_eq!(p.planner, k);
            assert_eq!(toml::to_string(&p).unwrap(), format!("planner = \"{}\"\ncontroller = \"dwa\"\n", k.name()));
        }
        let e = toml::from_str::<Plugins>("controller = \"mppi\"").unwrap_err();
        assert!(e.to_string().contains("controller = \"mppi\" is unknown; allowed: \"dwa\""), "{e}");
    }
}
