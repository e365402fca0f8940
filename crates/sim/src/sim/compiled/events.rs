//! Interning events and inferring the type of every event parameter from its sends.

use super::*;

impl<'s> Builder<'s> {
    pub(super) fn event(&mut self, name: &str) -> u32 {
        if let Some(&i) = self.event_index.get(name) {
            return i;
        }
        let i = self.events.len() as u32;
        self.events.push(EventB {
            name: name.to_string(),
            params: BTreeMap::new(),
            senders: BTreeSet::new(),
            receivers: BTreeSet::new(),
        });
        self.event_index.insert(name.to_string(), i);
        self.strings.intern(name);
        i
    }

    pub(super) fn collect_events(&mut self) {
        let src = self.src;
        for (mi, m) in src.machines.iter().enumerate() {
            let mi = mi as u32;
            for s in &m.states {
                for t in &s.transitions {
                    for e in &t.events {
                        let id = self.event(&e.name);
                        self.events[id as usize].receivers.insert(mi);
                    }
                }
            }
            let visit = |execs: &[Exec], b: &mut Builder<'_>| {
                walk(execs, &mut |x| match x {
                    Exec::Send(s) => {
                        let id = b.event(&s.event.name) as usize;
                        b.events[id].senders.insert(mi);
                        for p in &s.params {
                            b.events[id]
                                .params
                                .entry(p.name.name.clone())
                                .or_insert(None);
                        }
                    }
                    Exec::Raise { event, .. } => {
                        let id = b.event(&event.name) as usize;
                        b.events[id].senders.insert(mi);
                        b.events[id].receivers.insert(mi);
                    }
                    _ => {}
                });
            };
            for s in &m.states {
                visit(&s.onentry, self);
                visit(&s.onexit, self);
                for t in &s.transitions {
                    visit(&t.body, self);
                }
            }
        }
    }

    /// A warning at each transition event `a` of a model that sends `a.b` to the same
    /// machine without the transition naming it: W3C SCXML's descriptor `a` matches every
    /// event `a.*` (SCXML 1.0, section 3.12.1), hindsight matches names exactly, as SCAN
    /// does (`scan_scxml` builder, `ModelBuilder::event_index`: one channel index per
    /// name) and AS2FM does (one JANI action per name). Models from other SCXML tools may
    /// count on the prefix rule; nothing else would show that those events are dropped.
    pub(super) fn prefix_warnings(&mut self) {
        let src = self.src;
        // Only dotted events can be missed so: most models have none.
        if !self.events.iter().any(|e| e.name.contains('.')) {
            return;
        }
        // Per machine, the dotted events that reach it: its own raises and sends to
        // itself, sends that name it, and sends whose target is an expression.
        let names: Vec<&str> = src.machines.iter().map(|m| m.name.name.as_str()).collect();
        let mut reach: Vec<BTreeSet<&str>> = vec![BTreeSet::new(); src.machines.len()];
        for (mi, m) in src.machines.iter().enumerate() {
            let mut visit = |x: &'s Exec| match x {
                Exec::Raise { event, .. } if event.name.contains('.') => {
                    reach[mi].insert(event.name.as_str());
                }
                Exec::Send(send) if send.event.name.contains('.') => {
                    let to: Vec<usize> = match &send.target {
                        Some(SendTarget::Id(id)) => names
                            .iter()
                            .position(|n| *n == id.name)
                            .into_iter()
                            .collect(),
                        Some(SendTarget::Expr(_)) => (0..names.len()).collect(),
                        // Without a target: to the machines with a transition on it.
                        None => Vec::new(),
                    };
                    for t in to {
                        reach[t].insert(send.event.name.as_str());
                    }
                }
                _ => {}
            };
            for s in &m.states {
                walk(&s.onentry, &mut visit);
                walk(&s.onexit, &mut visit);
                for t in &s.transitions {
                    walk(&t.body, &mut visit);
                }
            }
        }
        for (mi, m) in src.machines.iter().enumerate() {
            for s in &m.states {
                for t in &s.transitions {
                    for d in &t.events {
                        let missed: Vec<&str> = reach[mi]
                            .iter()
                            .copied()
                            .filter(|e| {
                                e.strip_prefix(d.name.as_str())
                                    .is_some_and(|rest| rest.starts_with('.'))
                                    && !t.events.iter().any(|n| n.name == *e)
                            })
                            .collect();
                        let Some(first) = missed.first() else {
                            continue;
                        };
                        let more = match missed.len() {
                            1 => String::new(),
                            n => format!(" (and {} more)", n - 1),
                        };
                        self.warnings.push(src.sources.diag(
                            d.span,
                            format!(
                                "event `{first}`{more}, sent to `{}`, is not taken by this \
                                 `{}` transition: hindsight matches event names exactly, as SCAN \
                                 and AS2FM do (W3C SCXML would take it: a descriptor matches the \
                                 events it is a prefix of); add it to `event` to take it",
                                m.name.name, d.name
                            ),
                        ));
                    }
                }
            }
        }
    }

    /// Every `<send>` with the event in scope where it is compiled.
    pub(super) fn sites(&self) -> Vec<Site<'s>> {
        let src = self.src;
        let mut out = Vec::new();
        for (mi, m) in src.machines.iter().enumerate() {
            let mi = mi as u32;
            for s in &m.states {
                walk(&s.onentry, &mut |x| {
                    if let Exec::Send(send) = x {
                        out.push(Site {
                            machine: mi,
                            event: None,
                            send,
                        });
                    }
                });
                for t in &s.transitions {
                    let evs: Vec<Option<u32>> = if t.events.is_empty() {
                        vec![None]
                    } else {
                        t.events
                            .iter()
                            .map(|e| self.event_index.get(&e.name).copied())
                            .collect()
                    };
                    for ev in evs {
                        for block in [&s.onexit, &t.body] {
                            walk(block, &mut |x| {
                                if let Exec::Send(send) = x {
                                    out.push(Site {
                                        machine: mi,
                                        event: ev,
                                        send,
                                    });
                                }
                            });
                        }
                    }
                }
            }
        }
        out
    }

    /// Infers every event parameter's type from annotations and sent expressions (fixpoint).
    pub(super) fn infer_params(&mut self) {
        let sites = self.sites();
        // Annotations first.
        for site in &sites {
            let Some(&ev) = self.event_index.get(&site.send.event.name) else {
                continue;
            };
            for p in &site.send.params {
                if let Some(ann) = &p.ty {
                    if let Some(t) = self.resolve(&ann.ty, ann.span) {
                        self.merge_param(ev, &p.name.name, t);
                    }
                }
            }
        }
        let mut parsed: Vec<Vec<Option<crate::expr::ast::Expr>>> = sites
            .iter()
            .map(|s| {
                s.send
                    .params
                    .iter()
                    .map(|p| parse_expr(&p.expr.text).ok())
                    .collect()
            })
            .collect();
        for _round in 0..64 {
            let mut changed = false;
            for (si, site) in sites.iter().enumerate() {
                let Some(&ev) = self.event_index.get(&site.send.event.name) else {
                    continue;
                };
                for (pi, p) in site.send.params.iter().enumerate() {
                    if p.ty.is_some() {
                        continue;
                    }
                    let Some(Some(ast)) = parsed.get(si).and_then(|v| v.get(pi)) else {
                        continue;
                    };
                    if let Ok(t) = self.compile_in_site(site, ast) {
                        changed |= self.merge_param(ev, &p.name.name, t.ty);
                    }
                }
            }
            if !changed {
                break;
            }
        }
        parsed.clear();
        // Report parameters whose type is still unknown, at their first send.
        let mut reported = BTreeSet::new();
        for site in &sites {
            let Some(&ev) = self.event_index.get(&site.send.event.name) else {
                continue;
            };
            for p in &site.send.params {
                let t = self.events[ev as usize]
                    .params
                    .get(&p.name.name)
                    .cloned()
                    .flatten();
                let bad = match &t {
                    None => true,
                    Some(t) => contains_unknown(t),
                };
                if bad && reported.insert((ev, p.name.name.clone())) {
                    // Why the type is unknown: a syntax error, an expression that does
                    // not compile (an unknown variable, say), or one whose type says
                    // nothing (`[]`). Reads of the parameter elsewhere would only echo it.
                    self.failed_params
                        .insert(unknown_param_type(&p.name.name, &site.send.event.name));
                    match parse_expr(&p.expr.text) {
                        Err(pe) => {
                            let at = unescaped_offset(&self.src.sources, p.expr.span, pe.offset);
                            self.err(at, pe.message);
                        }
                        Ok(ast) => match self.compile_in_site(site, &ast) {
                            Err(e) => self.expr_err(site.machine, &p.expr, &e),
                            Ok(_) => {
                                let msg = format!(
                                    "cannot infer the type of parameter `{}` of event `{}` from its value: give the <param> a type (`type=\"int32\"`, or `<!-- TYPE {}:int32 -->` before it)",
                                    p.name.name, site.send.event.name, p.name.name
                                );
                                self.err(p.span, msg);
                            }
                        },
                    }
                }
            }
        }
    }

    /// Compiles a parameter expression of `site` in its machine's scope (the event's
    /// parameters as inferred so far), for the error it gives.
    pub(super) fn compile_in_site(
        &mut self,
        site: &Site<'_>,
        ast: &crate::expr::ast::Expr,
    ) -> Result<Typed, CompileError> {
        let scope_params: Vec<(String, Option<Ty>)> = match site.event {
            Some(e) => self.events[e as usize]
                .params
                .iter()
                .map(|(n, t)| (n.clone(), t.clone()))
                .collect(),
            None => Vec::new(),
        };
        let ename = site.event.map(|e| self.events[e as usize].name.clone());
        let abs = |k: u32| k;
        let scope = Scope {
            vars: &self.vars[site.machine as usize],
            event: match &ename {
                Some(n) => EventScope::Event {
                    name: n,
                    params: &scope_params,
                },
                None => EventScope::None,
            },
            types: &self.types,
            abs: &abs,
        };
        compile(ast, &scope, &mut self.strings, None)
    }

    /// Merges a sent type into a parameter's type; true when it changed.
    pub(super) fn merge_param(&mut self, ev: u32, name: &str, t: Ty) -> bool {
        let Some(slot) = self.events[ev as usize].params.get_mut(name) else {
            return false;
        };
        match slot {
            None => {
                *slot = Some(t);
                true
            }
            Some(u) => match crate::expr::compile::unify(u, &t) {
                Some(w) if w != *u => {
                    *u = w;
                    true
                }
                // Equal, or a conflict reported when the send is compiled.
                _ => false,
            },
        }
    }
}
