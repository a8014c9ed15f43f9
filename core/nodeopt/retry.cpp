#include "core/nodeopt/retry.h"

namespace qs {

bool fell_back(const NodeOptResult& r) {
  return r.fewest_foldovers_reverted || r.initial_reverted;
}

bool unembedded(const NodeOptResult& r) {
  return r.foldovers_final > 0 || r.untangled;
}

bool wants_keep_apart_retry(const NodeOptResult& first) {
  return !first.stopped && (unembedded(first) || fell_back(first));
}

bool keep_apart_retry_is_better(const NodeOptResult& run, const NodeOptResult& first) {
  if (run.foldovers_final != first.foldovers_final)
    return run.foldovers_final < first.foldovers_final;
  if (run.untangled != first.untangled) return !run.untangled;
  return run.E_final < first.E_final;
}

bool wants_sizing_retry(const NodeOptResult& first) {
  return !first.stopped && (unembedded(first) || first.initial_reverted);
}

bool sizing_retry_is_better(const NodeOptResult& run, const NodeOptResult& first) {
  if (run.foldovers_final != first.foldovers_final)
    return run.foldovers_final < first.foldovers_final;
  return (first.initial_reverted && !run.initial_reverted) || (first.untangled && !run.untangled);
}

}  // namespace qs
