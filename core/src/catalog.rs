//! The fruit catalog: names, appearance, size, shape and stiffness per ripeness stage, and the
//! ripeness thresholds explanations use. Loaded from `scenes/fruits.toml` (built in).

use serde::{Deserialize, Serialize};
use std::path::Path;

pub const BUILTIN_CATALOG: &str = include_str!("../../scenes/fruits.toml");

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FruitShape {
    Ellipsoid,
    /// An ellipsoid whose cross-section swells towards one end (avocado, strawberry).
    Egg,
    /// A tapered tube bent along an arc.
    Banana,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RipenessStage {
    pub name: String,
    pub modulus_mpa: f64,
    pub threshold_mpa: f64,
    pub color: [f64; 3],
    pub source: String,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FruitSpec {
    pub name: String,
    pub plural: String,
    #[serde(default)]
    pub synonyms: Vec<String>,
    /// The kitchen's groups it belongs to (`CategorySpec::name`): "citrus", "stone fruit".
    #[serde(default)]
    pub categories: Vec<String>,
    pub shape: FruitShape,
    pub size_m: [f64; 3],
    pub poisson: f64,
    pub default_stage: String,
    pub stages: Vec<RipenessStage>,
}

impl FruitSpec {
    pub fn stage(&self, name: &str) -> Option<&RipenessStage> {
        self.stages
            .iter()
            .find(|s| s.name.eq_ignore_ascii_case(name))
    }

    /// The stage a measured modulus falls in (stages are ordered hardest first).
    pub fn stage_for_modulus(&self, modulus_mpa: Option<f64>) -> &RipenessStage {
        let e = modulus_mpa.unwrap_or(f64::INFINITY);
        self.stages
            .iter()
            .find(|s| e >= s.threshold_mpa)
            .unwrap_or_else(|| self.stages.last().expect("validated non-empty"))
    }

    /// Whether explanations should speak of ripeness (more than one stage known).
    pub fn has_ripeness(&self) -> bool {
        self.stages.len() > 1
    }

    fn answers_to(&self, word: &str) -> bool {
        let w = word.to_ascii_lowercase();
        w == self.name || w == self.plural || self.synonyms.contains(&w)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum CatalogError {
    #[error("{path}: cannot read catalog: {message}")]
    Read { path: String, message: String },
    #[error("{path}: malformed catalog: {message}")]
    Malformed { path: String, message: String },
    #[error("{path}: fruit '{fruit}': {message}")]
    Invalid {
        path: String,
        fruit: String,
        message: String,
    },
}

/// A group of fruit a question may name ("the citrus fruits"), and the words that name it:
/// one to three lower-case words each ("stone fruit").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CategorySpec {
    pub name: String,
    /// How an answer names one of the group: "citrus fruit", "berry".
    pub noun: String,
    pub words: Vec<String>,
}

#[derive(Clone, Debug, Deserialize)]
struct CatalogFile {
    fruit: Vec<FruitSpec>,
    #[serde(default)]
    category: Vec<CategorySpec>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FruitCatalog {
    pub fruits: Vec<FruitSpec>,
    pub categories: Vec<CategorySpec>,
}

impl FruitCatalog {
    pub fn builtin() -> Self {
        Self::parse(BUILTIN_CATALOG, "scenes/fruits.toml (built in)")
            .expect("the built-in catalog is valid")
    }

    pub fn load(path: &Path) -> Result<Self, CatalogError> {
        let shown = path.display().to_string();
        let text = crate::text_file::read_to_string(path).map_err(|e| CatalogError::Read {
            path: shown.clone(),
            message: e.to_string(),
        })?;
        Self::parse(&text, &shown)
    }

    pub fn parse(text: &str, path: &str) -> Result<Self, CatalogError> {
        let file: CatalogFile = toml::from_str(text).map_err(|e| CatalogError::Malformed {
            path: path.into(),
            message: crate::file_failure::toml_failure(text, &e),
        })?;
        for f in &file.fruit {
            let bad = |message: String| CatalogError::Invalid {
                path: path.into(),
                fruit: f.name.clone(),
                message,
            };
            if f.stages.is_empty() {
                return Err(bad("no ripeness stages".into()));
            }
            if f.size_m.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
                return Err(bad("size_m must be finite and positive".into()));
            }
            if f.stage(&f.default_stage).is_none() {
                return Err(bad(format!(
                    "default_stage '{}' is not one of its stages",
                    f.default_stage
                )));
            }
            let mut previous = f64::INFINITY;
            for s in &f.stages {
                if !(s.modulus_mpa.is_finite() && s.modulus_mpa > 0.0)
                    || s.threshold_mpa > s.modulus_mpa
                    || s.threshold_mpa >= previous
                {
                    return Err(bad(format!(
                        "stage '{}': thresholds must decrease and lie below the stage modulus",
                        s.name
                    )));
                }
                previous = s.threshold_mpa;
            }
            if f.stages.last().is_some_and(|s| s.threshold_mpa != 0.0) {
                return Err(bad("the softest stage's threshold_mpa must be 0".into()));
            }
            if let Some(c) = f
                .categories
                .iter()
                .find(|c| !file.category.iter().any(|k| &k.name == *c))
            {
                return Err(bad(format!(
                    "categories: '{c}' is not a [[category]] of the catalog"
                )));
            }
        }
        for c in &file.category {
            let bad = |message: String| CatalogError::Malformed {
                path: path.into(),
                message: format!("category '{}': {message}", c.name),
            };
            if c.words.is_empty() {
                return Err(bad("words: none".into()));
            }
            let plain = |phrase: &str| {
                let parts: Vec<&str> = phrase.split(' ').collect();
                parts.len() <= 3
                    && parts
                        .iter()
                        .all(|p| !p.is_empty() && p.chars().all(|ch| ch.is_ascii_lowercase()))
            };
            if !plain(&c.noun) {
                return Err(bad(format!(
                    "noun: '{}' must be one to three lower-case words",
                    crate::printable::printable(&c.noun)
                )));
            }
            for w in &c.words {
                if !plain(w) {
                    return Err(bad(format!(
                        "words: '{}' must be one to three lower-case words",
                        crate::printable::printable(w)
                    )));
                }
                if file.fruit.iter().any(|f| f.answers_to(w)) {
                    return Err(bad(format!("words: '{w}' names a fruit")));
                }
            }
        }
        Ok(Self {
            fruits: file.fruit,
            categories: file.category,
        })
    }

    /// The category named by the words at the start of `words`, and how many words name it:
    /// the longest phrase that matches ("citrus fruits" before "citrus").
    pub fn category_at(&self, words: &[&str]) -> Option<(&CategorySpec, usize)> {
        self.categories
            .iter()
            .flat_map(|c| c.words.iter().map(move |w| (c, w)))
            .filter_map(|(c, w)| {
                let n = w.split(' ').count();
                (words.len() >= n && words[..n].join(" ") == *w).then_some((c, n))
            })
            .max_by_key(|(_, n)| *n)
    }

    /// The names of the fruit in a category, in catalog order.
    pub fn members(&self, category: &str) -> Vec<String> {
        self.fruits
            .iter()
            .filter(|f| f.categories.iter().any(|c| c == category))
            .map(|f| f.name.clone())
            .collect()
    }

    pub fn get(&self, name: &str) -> Option<&FruitSpec> {
        self.fruits
            .iter()
            .find(|f| f.name.eq_ignore_ascii_case(name))
    }

    /// The fruit a word names (singular, plural or synonym).
    pub fn find_word(&self, word: &str) -> Option<&FruitSpec> {
        self.fruits.iter().find(|f| f.answers_to(word))
    }

    pub fn names(&self) -> Vec<&str> {
        self.fruits.iter().map(|f| f.name.as_str()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_catalog_has_the_papers_fruits() {
        let c = FruitCatalog::builtin();
        for name in [
            "mango", "lime", "lemon", "tomato", "banana", "avocado", "kiwi", "apple", "orange",
            "peach",
        ] {
            assert!(c.get(name).is_some(), "{name} missing");
        }
        let banana = c.get("banana").unwrap();
        assert_eq!(banana.stage("ripe").unwrap().modulus_mpa, 0.8);
        assert_eq!(banana.stage("unripe").unwrap().modulus_mpa, 2.5);
        assert_eq!(c.find_word("tomatoes").unwrap().name, "tomato");
        assert_eq!(c.members("citrus"), ["lime", "lemon", "orange"]);
        let (stone, n) = c.category_at(&["stone", "fruits", "please"]).unwrap();
        assert_eq!((stone.name.as_str(), n), ("stone fruit", 2));
        assert!(c.category_at(&["stone"]).is_none());
    }

    #[test]
    fn every_stage_modulus_falls_in_its_own_threshold_band() {
        for f in FruitCatalog::builtin().fruits {
            for s in &f.stages {
                assert_eq!(
                    f.stage_for_modulus(Some(s.modulus_mpa)).name,
                    s.name,
                    "{} {}",
                    f.name,
                    s.name
                );
            }
            assert_eq!(
                f.stage_for_modulus(None).name,
                f.stages[0].name,
                "rigid reads as the hardest stage"
            );
        }
    }

    #[test]
    fn malformed_catalog_names_the_file() {
        let e = FruitCatalog::parse("[[fruit]]\nname = 3", "x.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("x.toml: malformed catalog"), "{e}");
    }
}
