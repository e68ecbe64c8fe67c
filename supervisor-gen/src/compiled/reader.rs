//! Reading a compiled supervisor-set file back, treating its bytes as hostile: every read is bounds-checked and
//! every count is checked against the bytes left before anything is allocated.

use super::{
    CompiledEvent, CompiledState, CompiledSupervisor, CompiledTransition, FORMAT_VERSION,
    FormatProblem, MAGIC, MAX_EVENTS, SupervisorSet,
};

/// A read that fails with the byte offset and what is wrong there.
type ParseResult<T> = Result<T, (usize, FormatProblem)>;

/// A bounds-checked cursor over untrusted bytes.
pub(super) struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    /// A reader at the start of `bytes`.
    pub(super) fn new(bytes: &'a [u8]) -> Reader<'a> {
        Reader { bytes, pos: 0 }
    }
}

impl Reader<'_> {
    fn take(&mut self, n: usize, what: &'static str) -> ParseResult<&[u8]> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&end| end <= self.bytes.len())
            .ok_or((self.pos, FormatProblem::Truncated(what)))?;
        let slice = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(slice)
    }

    fn u8(&mut self, what: &'static str) -> ParseResult<u8> {
        Ok(self.take(1, what)?[0])
    }

    fn u16(&mut self, what: &'static str) -> ParseResult<u16> {
        let b = self.take(2, what)?;
        Ok(u16::from_be_bytes([b[0], b[1]]))
    }

    fn flag(&mut self, what: &'static str) -> ParseResult<bool> {
        let at = self.pos;
        match self.u8(what)? {
            0 => Ok(false),
            1 => Ok(true),
            v => Err((at, FormatProblem::BadFlag(what, v))),
        }
    }

    fn name(&mut self, what: &'static str) -> ParseResult<String> {
        let len = usize::from(self.u16(what)?);
        let at = self.pos;
        let raw = self.take(len, what)?;
        std::str::from_utf8(raw)
            .map(str::to_owned)
            .map_err(|_| (at, FormatProblem::InvalidUtf8(what)))
    }

    pub(super) fn parse(mut self) -> ParseResult<SupervisorSet> {
        if self.take(4, "magic bytes")? != MAGIC {
            return Err((0, FormatProblem::BadMagic));
        }
        let version = self.u16("format version")?;
        if version != FORMAT_VERSION {
            return Err((4, FormatProblem::UnsupportedVersion(version)));
        }
        let e_at = self.pos;
        let e = self.u16("event count")?;
        if usize::from(e) > MAX_EVENTS {
            return Err((e_at, FormatProblem::TooManyEvents(e)));
        }
        let n = usize::from(self.u16("supervisor count")?);
        let mut names = Vec::with_capacity(usize::from(e));
        for _ in 0..e {
            names.push(self.name("event name")?);
        }
        // Each supervisor entry takes at least 4 bytes, which bounds the allocation by the input size.
        let mut sups = Vec::with_capacity(n.min(self.bytes.len() / 4));
        for i in 0..n {
            let name = self.name("supervisor name")?;
            let at = self.pos;
            let count = usize::from(self.u16("state count")?);
            if count == 0 {
                return Err((at, FormatProblem::NoStates { supervisor: i }));
            }
            sups.push((name, count));
        }
        // δ blocks are checked against the membership matrix, which comes after them: parse raw first.
        let mut raw = Vec::with_capacity(sups.len());
        for (i, &(_, count)) in sups.iter().enumerate() {
            raw.push(self.supervisor_arrays(i, count, usize::from(e))?);
        }
        let mut controllable = Vec::with_capacity(usize::from(e));
        for _ in 0..e {
            controllable.push(self.flag("controllability table")?);
        }
        let mut member = vec![false; usize::from(e) * n];
        for m in member.iter_mut() {
            *m = self.flag("membership matrix")?;
        }
        for i in 0..n {
            let at = self.pos;
            let cur = self.u16("current-state table")?;
            if cur != 0 {
                return Err((
                    at,
                    FormatProblem::NonInitialCurrentState {
                        supervisor: i,
                        state: cur,
                    },
                ));
            }
        }
        if self.pos != self.bytes.len() {
            return Err((
                self.pos,
                FormatProblem::TrailingBytes(self.bytes.len() - self.pos),
            ));
        }
        let events: Vec<CompiledEvent> = names
            .into_iter()
            .zip(&controllable)
            .map(|(name, &controllable)| CompiledEvent { name, controllable })
            .collect();
        let mut supervisors = Vec::with_capacity(n);
        for (i, ((name, _), arrays)) in sups.into_iter().zip(raw).enumerate() {
            let alphabet: Vec<u8> = (0..usize::from(e))
                .filter(|&ev| member[ev * n + i])
                .map(|ev| ev as u8)
                .collect();
            let states = arrays.assemble(i, &alphabet, &controllable)?;
            supervisors.push(CompiledSupervisor {
                name,
                alphabet,
                states,
            });
        }
        Ok(SupervisorSet {
            events,
            supervisors,
        })
    }

    fn supervisor_arrays(&mut self, sup: usize, count: usize, e: usize) -> ParseResult<RawArrays> {
        let mut delta = Vec::with_capacity(count);
        for state in 0..count {
            let at = self.pos;
            let k = self.u8("transition array")?;
            let mut trs = Vec::with_capacity(usize::from(k));
            for _ in 0..k {
                let event = self.u8("transition array")?;
                let target = self.u16("transition array")?;
                if usize::from(event) >= e {
                    return Err((
                        at,
                        FormatProblem::EventOutOfRange {
                            supervisor: sup,
                            state,
                            event,
                        },
                    ));
                }
                if usize::from(target) >= count {
                    return Err((
                        at,
                        FormatProblem::TargetOutOfRange {
                            supervisor: sup,
                            state,
                            target,
                        },
                    ));
                }
                trs.push((event, target));
            }
            delta.push((at, trs));
        }
        let probs = self.value_blocks(count, "probability array")?;
        let times = self.value_blocks(count, "time array")?;
        Ok(RawArrays {
            delta,
            probs,
            times,
        })
    }

    fn value_blocks(
        &mut self,
        count: usize,
        what: &'static str,
    ) -> ParseResult<Vec<(usize, Vec<u16>)>> {
        let mut blocks = Vec::with_capacity(count);
        for _ in 0..count {
            let at = self.pos;
            let k = self.u8(what)?;
            let mut vals = Vec::with_capacity(usize::from(k));
            for _ in 0..k {
                vals.push(self.u16(what)?);
            }
            blocks.push((at, vals));
        }
        Ok(blocks)
    }
}

/// One supervisor's δ, P and T arrays as read, with the offset of each state's block.
struct RawArrays {
    delta: Vec<(usize, Vec<(u8, u16)>)>,
    probs: Vec<(usize, Vec<u16>)>,
    times: Vec<(usize, Vec<u16>)>,
}

impl RawArrays {
    fn assemble(
        self,
        sup: usize,
        alphabet: &[u8],
        controllable: &[bool],
    ) -> ParseResult<Vec<CompiledState>> {
        let mut states = Vec::with_capacity(self.delta.len());
        for (state, (((at, trs), (p_at, probs)), (t_at, times))) in self
            .delta
            .into_iter()
            .zip(self.probs)
            .zip(self.times)
            .enumerate()
        {
            let ctrl = |ev: u8| controllable.get(usize::from(ev)).copied().unwrap_or(false);
            let key = |ev: u8| (!ctrl(ev), ev);
            if trs.windows(2).any(|w| key(w[0].0) >= key(w[1].0)) {
                return Err((
                    at,
                    FormatProblem::BadTransitionOrder {
                        supervisor: sup,
                        state,
                    },
                ));
            }
            if let Some(&(event, _)) = trs
                .iter()
                .find(|(ev, _)| alphabet.binary_search(ev).is_err())
            {
                return Err((
                    at,
                    FormatProblem::EventNotInAlphabet {
                        supervisor: sup,
                        state,
                        event,
                    },
                ));
            }
            let n_c = trs.iter().filter(|(ev, _)| ctrl(*ev)).count() as u8;
            for (block_at, array, found) in [
                (p_at, "probability", probs.len()),
                (t_at, "time", times.len()),
            ] {
                if found != usize::from(n_c) {
                    return Err((
                        block_at,
                        FormatProblem::CountMismatch {
                            supervisor: sup,
                            state,
                            array,
                            expected: n_c,
                            found: found as u8,
                        },
                    ));
                }
            }
            let transitions = trs
                .iter()
                .enumerate()
                .map(|(j, &(event, target))| {
                    let (prob_q16, lower_bound) = if ctrl(event) {
                        (probs[j], times[j])
                    } else {
                        (u16::MAX, 0)
                    };
                    CompiledTransition {
                        event,
                        target,
                        prob_q16,
                        lower_bound,
                    }
                })
                .collect();
            states.push(CompiledState { transitions });
        }
        Ok(states)
    }
}
