//! The teaching game's menu in Foxglove: the scene's switches offered through the WebSocket
//! protocol's Parameters capability. A value set in Foxglove's Parameters panel is checked
//! against the switch's range, queued, and applied by the session before the next tick's step,
//! where the loop records it as a switch (`/scene/switch`) exactly like a script's
//! `[[switch]]`: replay applies it on the same tick.

use foxglove::websocket::{Client, Parameter, ParameterValue, ServerListener};
use haptic_types::SwitchSpec;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

/// The menu's state, shared by the server's listener (sets arrive on its threads) and the
/// session (which applies them).
#[derive(Default)]
pub struct Menu {
    kind: String,
    specs: Vec<SwitchSpec>,
    values: BTreeMap<String, f64>,
    inbox: Vec<(String, f64)>,
}

impl Menu {
    /// Offers the switches `specs` of a `kind` scene, at their current `values`.
    pub fn offer(&mut self, kind: &str, specs: &[SwitchSpec], values: BTreeMap<String, f64>) {
        self.kind = kind.to_string();
        self.specs = specs.to_vec();
        self.values = values;
    }

    /// Takes the accepted sets since the last call, in arrival order (name, value).
    pub fn take(&mut self) -> Vec<(String, f64)> {
        std::mem::take(&mut self.inbox)
    }

    /// Records the value a switch has now (after the loop applied it, or refused it).
    pub fn set_value(&mut self, name: &str, value: f64) {
        self.values.insert(name.to_string(), value);
    }

    /// The parameters named (every switch when `names` is empty), at their current values.
    fn parameters(&self, names: &[String]) -> Vec<Parameter> {
        self.specs
            .iter()
            .filter(|s| names.is_empty() || names.iter().any(|n| n == s.name))
            .filter_map(|s| {
                let v = *self.values.get(s.name)?;
                Some(if s.boolean {
                    Parameter::bool(s.name, v != 0.0)
                } else {
                    Parameter::float64(s.name, v)
                })
            })
            .collect()
    }

    /// Checks and queues the sets of `params`; returns every named parameter at the value it
    /// will have (the new one when accepted, the old one when refused).
    fn set(&mut self, params: Vec<Parameter>) -> Vec<Parameter> {
        let mut names = Vec::new();
        for p in params {
            let value = match &p.value {
                Some(ParameterValue::Float64(v)) => Some(*v),
                Some(ParameterValue::Integer(i)) => Some(*i as f64),
                Some(ParameterValue::Bool(b)) => Some(f64::from(u8::from(*b))),
                _ => None,
            };
            if let Some(v) = value {
                if let Ok(spec) = haptic_types::switch::check(&self.kind, &self.specs, &p.name, v) {
                    self.inbox.push((spec.name.to_string(), v));
                    self.values.insert(spec.name.to_string(), v);
                }
            }
            names.push(p.name);
        }
        self.parameters(&names)
    }
}

/// The server's listener: answers Foxglove's get and set parameter requests from the menu.
pub struct MenuListener(pub Arc<Mutex<Menu>>);

impl ServerListener for MenuListener {
    fn on_get_parameters(
        &self,
        _client: Client,
        param_names: Vec<String>,
        _request_id: Option<&str>,
    ) -> Vec<Parameter> {
        self.0
            .lock()
            .map(|m| m.parameters(&param_names))
            .unwrap_or_default()
    }

    fn on_set_parameters(
        &self,
        _client: Client,
        parameters: Vec<Parameter>,
        _request_id: Option<&str>,
    ) -> Vec<Parameter> {
        self.0
            .lock()
            .map(|mut m| m.set(parameters))
            .unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPECS: [SwitchSpec; 2] = [
        SwitchSpec::number("gravity_m_per_s2", 0.0, 100.0, "gravity"),
        SwitchSpec::on_off("inertia", "inertia"),
    ];

    fn menu() -> Menu {
        let mut m = Menu::default();
        let values = [
            ("gravity_m_per_s2".to_string(), 9.81),
            ("inertia".to_string(), 1.0),
        ];
        m.offer("brickworld", &SPECS, values.into_iter().collect());
        m
    }

    #[test]
    fn sets_in_range_are_queued_and_others_keep_their_value() {
        let mut m = menu();
        let back = m.set(vec![
            Parameter::float64("gravity_m_per_s2", 2.5),
            Parameter::bool("inertia", false),
            Parameter::float64("gravity_m_per_s2", 150.0),
            Parameter::float64("moon", 1.0),
        ]);
        assert_eq!(
            m.take(),
            [
                ("gravity_m_per_s2".to_string(), 2.5),
                ("inertia".to_string(), 0.0)
            ]
        );
        assert!(m.take().is_empty());
        // The refused 150 m/s² leaves the accepted 2.5; an unknown name is not offered.
        let g = back
            .iter()
            .find(|p| p.name == "gravity_m_per_s2")
            .map(|p| p.value.clone());
        assert_eq!(g, Some(Some(ParameterValue::Float64(2.5))));
        assert!(back.iter().all(|p| p.name != "moon"));
        assert_eq!(m.parameters(&[]).len(), 2);
    }
}
