//! A user's own presets ("looks"): the media and lighting of a scene saved under a name. The
//! app keeps them (browser storage, the data folder natively), not any document, and applies
//! one to any scene as one undoable edit. The shape of the cloud is never part of a look.

use serde::{Deserialize, Serialize};

use super::{Lighting, RenderSettings, Scene};
use crate::limits::{MAX_FILE_BYTES, MAX_LOOK_NAME, MAX_LOOKS};

/// Media and lighting under a name.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Look {
    /// The name it is listed under.
    pub name: String,
    /// Sun, sky, scattering and background.
    pub light: Lighting,
    /// Render quality and the cloud's media.
    pub render: RenderSettings,
}

impl Look {
    /// `scene` with this look's light and media (its field grid kept: that samples the shape).
    pub fn applied_to(&self, scene: &Scene) -> Scene {
        let mut out = scene.clone();
        out.light = self.light.clone();
        out.render = RenderSettings {
            field_resolution: scene.render.field_resolution,
            ..self.render.clone()
        };
        out
    }
}

/// Every look a user has saved, in the order saved.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Looks {
    /// The looks.
    pub looks: Vec<Look>,
}

/// A name made fit for the list: trimmed, at most [`MAX_LOOK_NAME`] characters.
fn clean_name(name: &str) -> String {
    name.trim()
        .chars()
        .filter(|c| !c.is_control())
        .take(MAX_LOOK_NAME)
        .collect()
}

impl Looks {
    /// Reads the stored list, repairing what it can (values out of range clamped, names
    /// trimmed, at most [`MAX_LOOKS`] kept).
    pub fn from_json(text: &str) -> Result<Self, String> {
        if text.len() as u64 > MAX_FILE_BYTES {
            return Err("the saved presets are too large".into());
        }
        let mut looks: Looks =
            serde_json::from_str(text).map_err(|e| format!("the saved presets: {e}"))?;
        looks.looks.truncate(MAX_LOOKS);
        for look in &mut looks.looks {
            look.name = clean_name(&look.name);
            look.light.sanitize();
            look.render.sanitize();
        }
        looks.looks.retain(|l| !l.name.is_empty());
        Ok(looks)
    }

    /// The list as JSON, for the app's store.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// Saves `scene`'s media and lighting as `name` (replacing a look of that name). Returns
    /// the name as kept.
    pub fn save(&mut self, name: &str, scene: &Scene) -> Result<String, String> {
        let name = clean_name(name);
        if name.is_empty() {
            return Err("give the preset a name".into());
        }
        let look = Look {
            name: name.clone(),
            light: scene.light.clone(),
            render: scene.render.clone(),
        };
        let full = self.looks.len() >= MAX_LOOKS;
        match self.looks.iter_mut().find(|l| l.name == name) {
            Some(old) => *old = look,
            None if full => {
                return Err(format!(
                    "{MAX_LOOKS} presets are kept at most: delete one first"
                ));
            }
            None => self.looks.push(look),
        }
        Ok(name)
    }

    /// Deletes the look called `name`, if any.
    pub fn remove(&mut self, name: &str) {
        self.looks.retain(|l| l.name != name);
    }

    /// The look called `name`.
    pub fn get(&self, name: &str) -> Option<&Look> {
        self.looks.iter().find(|l| l.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{NoiseFilter, Preset};

    #[test]
    fn a_look_carries_media_and_light_and_never_the_shape() {
        let sunset = Scene::preset(Preset::Sunset);
        let mut looks = Looks::default();
        assert_eq!(
            looks.save("  golden hour ", &sunset).unwrap(),
            "golden hour"
        );
        let cumulus = Scene::preset(Preset::Cumulus);
        let applied = looks.get("golden hour").unwrap().applied_to(&cumulus);
        assert_eq!(applied.light, sunset.light);
        assert_eq!(applied.render.noise_filter, sunset.render.noise_filter);
        assert_eq!(
            applied.render.field_resolution,
            cumulus.render.field_resolution
        );
        assert_eq!(applied.ellipsoids, cumulus.ellipsoids);
        assert_eq!(applied.camera, cumulus.camera);
        assert_ne!(applied.light, cumulus.light, "the look changed something");

        // The same name replaces; the list survives its JSON; a bad list is an error.
        let mut wispy = cumulus.clone();
        wispy.render.noise_filter = NoiseFilter::Wispy;
        looks.save("golden hour", &wispy).unwrap();
        assert_eq!(looks.looks.len(), 1);
        let back = Looks::from_json(&looks.to_json()).unwrap();
        assert_eq!(back, looks);
        assert!(Looks::from_json("{\"looks\": 3}").is_err());
        assert!(looks.save("   ", &cumulus).is_err());
        looks.remove("golden hour");
        assert!(looks.looks.is_empty());
    }

    #[test]
    fn a_stored_list_is_capped_and_repaired() {
        let many: Vec<String> = (0..40)
            .map(|i| format!("{{\"name\":\"p{i}\",\"light\":{{\"ambient\":1e9}}}}"))
            .collect();
        let looks = Looks::from_json(&format!("{{\"looks\":[{}]}}", many.join(","))).unwrap();
        assert_eq!(looks.looks.len(), MAX_LOOKS);
        assert!(looks.looks[0].light.ambient <= crate::limits::AMBIENT.max as f32);
        let mut full = looks.clone();
        let err = full.save("one more", &Scene::default()).unwrap_err();
        assert!(err.contains("at most"), "{err}");
        let long = "x".repeat(100);
        let mut one = Looks::default();
        assert_eq!(
            one.save(&long, &Scene::default()).unwrap().len(),
            MAX_LOOK_NAME
        );
    }
}
