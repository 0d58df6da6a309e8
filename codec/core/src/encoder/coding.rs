//! Entropy coding of one conquest pass, from what the pass recorded and the
//! coarse mesh it left — the mesh the decoder holds before undoing it.
//!
//! Coding needs nothing of the simplifier's later state, so the encoder can
//! hand each pass to a second thread and go on simplifying ([`PassSink`]).

use std::sync::mpsc::{sync_channel, SyncSender};
use std::thread::{Scope, ScopedJoinHandle};

use crate::contexts::DECIMATION_SYMBOLS;
use crate::entropy::{BitModel, FrequencyModel, RangeEncoder};
use crate::gates::{GateCodes, PassKind, Traversal, Walked};
use crate::halfedge::Connectivity;
use crate::patch::MAX_VALENCE;
use crate::predict::{
    encode_colour, predict_colour, umbrellas, PassModels, PatchPrediction, PREDICTION_BLOCK,
};
use crate::{Error, Result};

/// What one pass decided, in the simplifier's current vertex ids.
pub(crate) struct PassRecord {
    pub kind: PassKind,
    /// Seed gates, one per connected component.
    pub seeds: Vec<[u32; 2]>,
    /// Each gate's decision in traversal order: 0 (null patch) or `valence − 2`.
    pub decisions: Vec<u8>,
    /// Removed vertices with their border polygons, in removal order.
    pub patches: Vec<(u32, usize, [u32; MAX_VALENCE])>,
    /// The seeds and the removed vertices in input-vertex ids.
    pub input_seeds: Vec<[u32; 2]>,
    pub input_removed: Vec<u32>,
}

/// The mesh a pass left behind (dead slots included), with the positions and
/// colours of every vertex the pass started with, removed ones too.
#[derive(Clone, Copy)]
pub(crate) struct CoarseMesh<'a> {
    pub conn: &'a Connectivity,
    pub positions: &'a [[i32; 3]],
    pub colours: Option<&'a [[u8; 3]]>,
}

/// A [`CoarseMesh`] of its own, to code on another thread.
pub(crate) struct CoarseSnapshot {
    conn: Connectivity,
    positions: Vec<[i32; 3]>,
    colours: Option<Vec<[u8; 3]>>,
}

impl CoarseSnapshot {
    pub(crate) fn of(mesh: CoarseMesh<'_>) -> Self {
        CoarseSnapshot {
            conn: mesh.conn.clone(),
            positions: mesh.positions.to_vec(),
            colours: mesh.colours.map(<[_]>::to_vec),
        }
    }

    pub(crate) fn mesh(&self) -> CoarseMesh<'_> {
        CoarseMesh {
            conn: &self.conn,
            positions: &self.positions,
            colours: self.colours.as_deref(),
        }
    }
}

/// What one pass produced, in input-vertex ids.
pub(crate) struct PassOutput {
    pub seeds: Vec<[u32; 2]>,
    /// Removed input vertices, in the order the decoder will insert them.
    pub removed: Vec<u32>,
    pub connectivity: Vec<u8>,
    pub geometry: Vec<u8>,
    pub colour: Vec<u8>,
}

impl PassOutput {
    /// A pass that removes nothing: the decoder skips it.
    pub(crate) fn empty() -> Self {
        PassOutput {
            seeds: Vec::new(),
            removed: Vec::new(),
            connectivity: Vec::new(),
            geometry: Vec::new(),
            colour: Vec::new(),
        }
    }
}

/// Where the encoder sends each pass to be coded: a second thread that codes
/// it from a snapshot while simplification goes on (at most one snapshot
/// waits, which bounds the extra memory to two meshes), or, when not
/// pipelined or without threads (WebAssembly), the encoding thread itself.
pub(crate) enum PassSink<'scope> {
    Thread {
        passes: SyncSender<(CoarseSnapshot, PassRecord)>,
        coder: ScopedJoinHandle<'scope, Result<Vec<PassOutput>>>,
    },
    InPlace {
        coder: Box<PassCoder>,
        outputs: Vec<PassOutput>,
    },
}

impl<'scope> PassSink<'scope> {
    pub(crate) fn start(scope: &'scope Scope<'scope, '_>, pipelined: bool) -> Self {
        if pipelined {
            let (passes, received) = sync_channel::<(CoarseSnapshot, PassRecord)>(1);
            let spawned = std::thread::Builder::new()
                .name("vitrine-pass-coder".into())
                .spawn_scoped(scope, move || {
                    let mut coder = PassCoder::default();
                    received
                        .into_iter()
                        .map(|(mesh, record)| coder.code(mesh.mesh(), record))
                        .collect()
                });
            if let Ok(coder) = spawned {
                return PassSink::Thread { passes, coder };
            }
        }
        PassSink::InPlace {
            coder: Box::default(),
            outputs: Vec::new(),
        }
    }

    /// Codes (or queues) one pass; `false` when the coding thread has
    /// stopped, whose error [`PassSink::finish`] returns.
    pub(crate) fn send(&mut self, mesh: CoarseMesh<'_>, record: PassRecord) -> Result<bool> {
        match self {
            PassSink::Thread { passes, .. } => {
                Ok(passes.send((CoarseSnapshot::of(mesh), record)).is_ok())
            }
            PassSink::InPlace { coder, outputs } => {
                outputs.push(coder.code(mesh, record)?);
                Ok(true)
            }
        }
    }

    /// Every pass sent, coded, in order.
    pub(crate) fn finish(self) -> Result<Vec<PassOutput>> {
        match self {
            PassSink::Thread { passes, coder } => {
                drop(passes);
                coder
                    .join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            }
            PassSink::InPlace { outputs, .. } => Ok(outputs),
        }
    }
}

/// Scratch reused from pass to pass.
#[derive(Default)]
pub(crate) struct PassCoder {
    replay: Traversal,
    umbrellas: Vec<[i32; 4]>,
    valences: Vec<u8>,
    predictions: Vec<PatchPrediction>,
}

impl PassCoder {
    pub(crate) fn code(&mut self, mesh: CoarseMesh<'_>, pass: PassRecord) -> Result<PassOutput> {
        // Codes and geometry both use the whole coarse mesh, which is what
        // the decoder has before it inserts anything.
        umbrellas(
            mesh.conn,
            mesh.positions,
            &mut self.umbrellas,
            &mut self.valences,
        );
        let connectivity = self.code_decisions(mesh, &pass)?;
        let mut models = PassModels::new();
        let mut geom = RangeEncoder::new();
        let mut colour = RangeEncoder::new();
        let predictions = &mut self.predictions;
        for block in pass.patches.chunks(PREDICTION_BLOCK) {
            predictions.clear();
            predictions.extend(block.iter().map(|(_, valence, polygon)| {
                PatchPrediction::for_border(&polygon[..*valence], mesh.positions, &self.umbrellas)
            }));
            for (&(centre, valence, polygon), prediction) in block.iter().zip(predictions.iter()) {
                prediction.encode(mesh.positions[centre as usize], &mut models, &mut geom);
                let Some(colours) = mesh.colours else {
                    continue;
                };
                let border = &polygon[..valence];
                let mut around = [[0u8; 3]; MAX_VALENCE];
                for (c, &v) in around.iter_mut().zip(border) {
                    *c = colours[v as usize];
                }
                encode_colour(
                    colours[centre as usize],
                    predict_colour(&around[..valence]),
                    &mut models,
                    &mut colour,
                );
            }
        }
        Ok(PassOutput {
            seeds: pass.input_seeds,
            removed: pass.input_removed,
            connectivity,
            geometry: geom.finish(),
            colour: colour.finish(),
        })
    }

    /// Codes the pass's decisions by replaying them through the decoder's
    /// traversal of the coarse mesh, and checks that it finds the very
    /// patches the encoder removed.
    fn code_decisions(&mut self, mesh: CoarseMesh<'_>, pass: &PassRecord) -> Result<Vec<u8>> {
        let mut replay = Replay {
            decisions: pass.decisions.iter(),
            enc: RangeEncoder::new(),
        };
        let disagree = || {
            Error::Unsupported(
                "internal error: the decoder's traversal disagrees with the encoder's".into(),
            )
        };
        self.replay
            .run(
                &mut Walked(mesh.conn),
                &self.valences,
                pass.kind,
                &pass.seeds,
                pass.patches.len(),
                &mut replay,
            )
            .map_err(|_| disagree())?;
        let same_patches = replay.decisions.as_slice().is_empty()
            && self.replay.borders.len() == pass.patches.len()
            && self
                .replay
                .borders
                .iter()
                .zip(&pass.patches)
                .all(|(r, (_, d, polygon))| r.valence == *d && r.polygon[..*d] == polygon[..*d]);
        if !same_patches {
            return Err(disagree());
        }
        Ok(replay.enc.finish())
    }
}

/// The encoder's decisions, coded as the decoder's traversal asks for them.
struct Replay<'a> {
    decisions: std::slice::Iter<'a, u8>,
    enc: RangeEncoder,
}

impl Replay<'_> {
    fn next(&mut self) -> Result<usize> {
        let d = self.decisions.next().ok_or_else(|| {
            Error::Unsupported("internal error: the replay ran out of decisions".into())
        })?;
        Ok(*d as usize)
    }
}

impl GateCodes for Replay<'_> {
    fn decimation(
        &mut self,
        model: &mut FrequencyModel<DECIMATION_SYMBOLS>,
        limit: usize,
    ) -> Result<usize> {
        let sym = self.next()?;
        if sym >= limit {
            return Err(Error::Unsupported(
                "internal error: a removed vertex's patch does not fit the coarse mesh".into(),
            ));
        }
        self.enc.encode_symbol_below(model, sym, limit);
        Ok(sym)
    }

    fn cleaning(&mut self, model: &mut BitModel) -> Result<bool> {
        let bit = self.next()? != 0;
        self.enc.encode_bit(model, bit);
        Ok(bit)
    }
}
