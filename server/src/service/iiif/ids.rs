//! The URIs of everything a model's IIIF description names. Each is under
//! `/iiif/{slug}/`, so an import can tell a target on this model's Scene
//! from one on another's.

/// The IIIF Presentation 4 JSON-LD context.
pub const CONTEXT: &str = "http://iiif.io/api/presentation/4/context.json";

/// What IIIF resources are served as (Presentation 4's media type profile).
pub const MEDIA_TYPE: &str =
    "application/ld+json;profile=\"http://iiif.io/api/presentation/4/context.json\"";

/// The URIs of one model's resources, absolute under the site's base.
pub struct Ids<'a> {
    pub base: &'a str,
    pub slug: &'a str,
}

impl Ids<'_> {
    fn under(&self, rest: &str) -> String {
        format!("{}/iiif/{}/{rest}", self.base, self.slug)
    }

    pub fn manifest(&self) -> String {
        self.under("manifest")
    }

    pub fn scene(&self) -> String {
        self.under(SCENE)
    }

    /// The Scene's painting page and its annotations (`model`, `camera`, …).
    pub fn painting(&self, what: &str) -> String {
        self.under(&format!("{SCENE}/painting/{what}"))
    }

    /// A camera or light painted into the Scene.
    pub fn scene_component(&self, what: &str) -> String {
        self.under(&format!("{SCENE}/{what}"))
    }

    /// The commenting annotations' page (also served at this URI).
    pub fn annotations(&self) -> String {
        self.under("annotations")
    }

    pub fn annotation(&self, id: i64) -> String {
        self.under(&format!("annotations/{id}"))
    }

    /// A guided tour's Range (`iiif/tours.rs`), and its steps (from 1).
    pub fn tour(&self, id: i64) -> String {
        self.under(&format!("tours/{id}"))
    }

    pub fn tour_step(&self, id: i64, step: usize) -> String {
        self.under(&format!("tours/{id}/steps/{step}"))
    }

    /// Where the target of an imported annotation must end: this model's
    /// Scene on any host (behind a proxy the exporter may have known the
    /// site by another name).
    pub fn scene_path(slug: &str) -> String {
        format!("/iiif/{slug}/{SCENE}")
    }
}

const SCENE: &str = "scene";

/// The collection of every public model.
pub fn collection(base: &str) -> String {
    format!("{base}/iiif/collection")
}
