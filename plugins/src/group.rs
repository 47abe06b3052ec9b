//! Pipeline groups: an ordered, editable list of plugins.
//!
//! Entries are identified by their plugin type (the first entry of that type), by a label
//! (unique within the group; default: the plugin's name, made unique with `#2`, `#3`, ...) or
//! by index, so one group can hold several configured instances of one plugin type.

use std::any::TypeId;
use std::sync::Arc;

use crate::app::{SimApp, SimPlugin};

/// An edit that names an entry the group does not have.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("pipeline group has no plugin {0}")]
pub struct GroupError(pub String);

#[derive(Clone)]
struct Entry {
    type_id: TypeId,
    type_name: &'static str,
    label: String,
    plugin: Arc<dyn SimPlugin>,
    enabled: bool,
}

/// An ordered list of plugins forming a pipeline. Users disable, replace, configure and add
/// plugins before building.
///
/// ```
/// use magsep_plugins::packing::{packing_pipeline, McmOverlapRemovalPlugin, PackingObservePlugin};
/// use magsep_plugins::core::CorePlugin;
/// let group = packing_pipeline().disable::<PackingObservePlugin>();
/// assert!(!group.contains::<PackingObservePlugin>());
/// let group = group.add_after::<CorePlugin, _>(CorePlugin).unwrap();
/// assert_eq!(group.labels()[..2], ["CorePlugin", "CorePlugin#2"]);
/// assert!(group.add_before::<McmOverlapRemovalPlugin, _>(CorePlugin).is_ok());
/// ```
#[derive(Clone, Default)]
pub struct PipelineGroup {
    entries: Vec<Entry>,
}

impl PipelineGroup {
    /// An empty group.
    pub fn new() -> Self {
        Self::default()
    }

    fn entry<P: SimPlugin>(&self, label: Option<String>, plugin: P) -> Entry {
        let plugin: Arc<dyn SimPlugin> = Arc::new(plugin);
        let base = label.unwrap_or_else(|| plugin.name());
        let mut label = base.clone();
        let mut k = 1;
        while self.entries.iter().any(|e| e.label == label) {
            k += 1;
            label = format!("{base}#{k}");
        }
        Entry {
            type_id: TypeId::of::<P>(),
            type_name: std::any::type_name::<P>(),
            label,
            plugin,
            enabled: true,
        }
    }

    fn index_of<P: SimPlugin>(&self) -> Result<usize, GroupError> {
        self.entries
            .iter()
            .position(|e| e.type_id == TypeId::of::<P>())
            .ok_or_else(|| GroupError(std::any::type_name::<P>().into()))
    }

    /// Append `plugin` (enabled). (Named like bevy's `PluginGroupBuilder::add`.)
    #[allow(clippy::should_implement_trait)]
    pub fn add<P: SimPlugin>(mut self, plugin: P) -> Self {
        let e = self.entry(None, plugin);
        self.entries.push(e);
        self
    }

    /// Append `plugin` under `label` (made unique with `#2`, ... if taken).
    pub fn add_labelled<P: SimPlugin>(mut self, label: impl Into<String>, plugin: P) -> Self {
        let e = self.entry(Some(label.into()), plugin);
        self.entries.push(e);
        self
    }

    /// Insert `plugin` before the first plugin of type `P`.
    ///
    /// # Errors
    /// [`GroupError`] when the group has no `P`.
    pub fn add_before<P: SimPlugin, N: SimPlugin>(mut self, plugin: N) -> Result<Self, GroupError> {
        let i = self.index_of::<P>()?;
        let e = self.entry(None, plugin);
        self.entries.insert(i, e);
        Ok(self)
    }

    /// Insert `plugin` after the first plugin of type `P`.
    ///
    /// # Errors
    /// [`GroupError`] when the group has no `P`.
    pub fn add_after<P: SimPlugin, N: SimPlugin>(mut self, plugin: N) -> Result<Self, GroupError> {
        let i = self.index_of::<P>()?;
        let e = self.entry(None, plugin);
        self.entries.insert(i + 1, e);
        Ok(self)
    }

    /// Replace the first plugin of type `P` by the configured instance `plugin` (same place,
    /// label kept, enabled); append it if the group has no `P`.
    pub fn set<P: SimPlugin>(mut self, plugin: P) -> Self {
        match self.index_of::<P>() {
            Ok(i) => {
                self.entries[i].plugin = Arc::new(plugin);
                self.entries[i].enabled = true;
                self
            }
            Err(_) => self.add(plugin),
        }
    }

    /// Replace the first plugin of type `Old` by `new` (same place, enabled, labelled by
    /// `new`'s name).
    ///
    /// # Errors
    /// [`GroupError`] when the group has no `Old`.
    pub fn replace<Old: SimPlugin, N: SimPlugin>(mut self, new: N) -> Result<Self, GroupError> {
        let i = self.index_of::<Old>()?;
        self.entries.remove(i);
        let e = self.entry(None, new);
        self.entries.insert(i, e);
        Ok(self)
    }

    /// Replace the entry labelled `label` by `plugin` (label kept, enabled).
    ///
    /// # Errors
    /// [`GroupError`] when no entry has that label.
    pub fn set_labelled<P: SimPlugin>(
        mut self,
        label: &str,
        plugin: P,
    ) -> Result<Self, GroupError> {
        let i = self
            .entries
            .iter()
            .position(|e| e.label == label)
            .ok_or_else(|| GroupError(format!("labelled {label:?}")))?;
        let mut e = self.entry(Some(label.into()), plugin);
        e.label = label.into();
        self.entries[i] = e;
        Ok(self)
    }

    /// Disable every plugin of type `P`.
    pub fn disable<P: SimPlugin>(mut self) -> Self {
        for e in &mut self.entries {
            if e.type_id == TypeId::of::<P>() {
                e.enabled = false;
            }
        }
        self
    }

    /// Enable or disable the entry at `index` (no-op when out of range).
    pub fn set_enabled(mut self, index: usize, enabled: bool) -> Self {
        if let Some(e) = self.entries.get_mut(index) {
            e.enabled = enabled;
        }
        self
    }

    /// Enable or disable the entry labelled `label`.
    ///
    /// # Errors
    /// [`GroupError`] when no entry has that label.
    pub fn set_enabled_labelled(mut self, label: &str, enabled: bool) -> Result<Self, GroupError> {
        let e = self
            .entries
            .iter_mut()
            .find(|e| e.label == label)
            .ok_or_else(|| GroupError(format!("labelled {label:?}")))?;
        e.enabled = enabled;
        Ok(self)
    }

    /// Whether an enabled plugin of type `P` is in the group.
    pub fn contains<P: SimPlugin>(&self) -> bool {
        self.entries
            .iter()
            .any(|e| e.type_id == TypeId::of::<P>() && e.enabled)
    }

    /// The enabled plugins of type `P`, in order (several configured instances).
    pub fn get_all<P: SimPlugin + Clone>(&self) -> Vec<P> {
        self.entries
            .iter()
            .filter(|e| e.enabled && e.type_id == TypeId::of::<P>())
            .filter_map(|e| (e.plugin.as_ref() as &dyn std::any::Any).downcast_ref::<P>())
            .cloned()
            .collect()
    }

    /// Names of the enabled plugins, in order.
    pub fn names(&self) -> Vec<String> {
        self.entries
            .iter()
            .filter(|e| e.enabled)
            .map(|e| e.plugin.name())
            .collect()
    }

    /// Labels of all entries (enabled or not), in order; an entry's index is its place here.
    pub fn labels(&self) -> Vec<String> {
        self.entries.iter().map(|e| e.label.clone()).collect()
    }

    /// (label, type name, parameters, enabled) of every entry, in order.
    pub fn infos(&self) -> Vec<(String, &'static str, serde_json::Value, bool)> {
        self.entries
            .iter()
            .map(|e| (e.label.clone(), e.type_name, e.plugin.params(), e.enabled))
            .collect()
    }

    /// Build the enabled plugins into `app`, in order, each under its label.
    pub fn build(&self, app: &mut SimApp) {
        for e in &self.entries {
            if e.enabled {
                app.add_named_plugin(e.label.clone(), e.plugin.clone());
            }
        }
    }
}
