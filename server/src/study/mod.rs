//! The subjective quality study (thesis §6.6): which transitions a
//! participant is shown ([`plan`]), what their answers say about the model's
//! good-enough level ([`analysis`]), and the CSV that answers gathered
//! elsewhere come in and go out as ([`csv`]). No storage and no HTTP here:
//! `storage::study` keeps the rows, `service::study` and `commands::study`
//! drive them.

pub mod analysis;
pub mod csv;
pub mod plan;

pub use analysis::{good_level, report, Judgement, Report, SessionAnswers};
pub use plan::{Improvement, Step, Transition};

/// Invitations look like `inv_` and 64 hex digits, so they are told from
/// researcher tokens (`vtr_…`) without a lookup, and leaked ones are easy to
/// grep for.
pub const INVITATION_PREFIX: &str = "inv_";

pub fn new_invitation() -> String {
    format!(
        "{INVITATION_PREFIX}{}",
        hex::encode(rand::random::<[u8; 32]>())
    )
}

pub fn is_invitation(token: &str) -> bool {
    token.starts_with(INVITATION_PREFIX)
}
