//! Pipeline groups: an ordered, editable list of plugins.

use std::any::TypeId;
use std::sync::Arc;

use crate::app::{SimApp, SimPlugin};

/// An ordered list of plugins forming a pipeline. Users disable built-in plugins and add
/// their own before building.
///
/// ```
/// use magsep_plugins::packing::{packing_pipeline, PackingObservePlugin};
/// let group = packing_pipeline().disable::<PackingObservePlugin>();
/// assert!(!group.contains::<PackingObservePlugin>());
/// ```
#[derive(Clone, Default)]
pub struct PipelineGroup {
    entries: Vec<(TypeId, Arc<dyn SimPlugin>, bool)>,
}

impl PipelineGroup {
    /// An empty group.
    pub fn new() -> Self {
        Self::default()
    }

    /// Append `plugin` (enabled). (Named like bevy's `PluginGroupBuilder::add`.)
    #[allow(clippy::should_implement_trait)]
    pub fn add<P: SimPlugin>(mut self, plugin: P) -> Self {
        self.entries
            .push((TypeId::of::<P>(), Arc::new(plugin), true));
        self
    }

    /// Disable every plugin of type `P`.
    pub fn disable<P: SimPlugin>(mut self) -> Self {
        for e in &mut self.entries {
            if e.0 == TypeId::of::<P>() {
                e.2 = false;
            }
        }
        self
    }

    /// Whether an enabled plugin of type `P` is in the group.
    pub fn contains<P: SimPlugin>(&self) -> bool {
        self.entries.iter().any(|e| e.0 == TypeId::of::<P>() && e.2)
    }

    /// Names of the enabled plugins, in order.
    pub fn names(&self) -> Vec<String> {
        self.entries
            .iter()
            .filter(|e| e.2)
            .map(|e| e.1.name())
            .collect()
    }

    /// Build the enabled plugins into `app`, in order.
    pub fn build(&self, app: &mut SimApp) {
        for (_, p, enabled) in &self.entries {
            if *enabled {
                app.add_boxed_plugin(p.clone());
            }
        }
    }
}
