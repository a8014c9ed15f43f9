// When `optimize` runs the node optimization again from the input, and which run it keeps
// (the command line's keep-apart and sizing retries, docs/interfaces.md). Pure rules on the
// results of the node optimization (optimizer.h), so that each case is testable without a
// model that happens to reach it.
#pragma once

#include "core/nodeopt/optimizer.h"

namespace qs {

//! The fold-over removal returned an earlier state than the final one: the accepted state with
//! the fewest fold-overs or the initial state (the node movement partly or wholly given up).
bool fell_back(const NodeOptResult& r);

//! Fold-overs remain, or only the untangling removed them (the orientation constraints failed at
//! every state tried; an untangled map keeps its state's parametric cones).
bool unembedded(const NodeOptResult& r);

//! The keep-apart retry (NodeOptOptions::Moves::keep_nodes_apart) is wanted after \p first, not
//! stopped early, when fold-overs remain, only the untangling removed them, or the removal fell
//! back to an earlier state (whether the user left the choice to the default is the caller's
//! check).
bool wants_keep_apart_retry(const NodeOptResult& first);

//! The keep-apart retry \p run replaces \p first when it ends with fewer fold-overs; at as many,
//! when it needs no untangling where \p first did; at that too, when its E is lower.
bool keep_apart_retry_is_better(const NodeOptResult& run, const NodeOptResult& first);

//! The sizing retry (ParamOptions::sizing) is wanted after \p first, not stopped early, when
//! fold-overs remain, only the untangling removed them, or the run embedded only its initial
//! state (the node movement given up); the user's explicit choice is the caller's check.
bool wants_sizing_retry(const NodeOptResult& first);

//! The sizing retry \p run replaces \p first when it ends with fewer fold-overs, or with as many
//! without falling back to the initial state where \p first did, or without the untangling where
//! \p first needed it. E is no criterion: the sizing field changes the energy.
bool sizing_retry_is_better(const NodeOptResult& run, const NodeOptResult& first);

}  // namespace qs
