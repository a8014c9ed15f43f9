// The rules of optimize's retries (core/nodeopt/retry.h) on results made to order: each branch,
// including those that real models reach only on some machines (a run that falls back to its
// initial state: the exact cow and cat, or the displaced spot with nodes kept apart on an AMD
// EPYC but not on an Intel Xeon). Real runs: rocker_arm_cli_test.cpp.
#include "core/nodeopt/retry.h"

#include <gtest/gtest.h>

namespace qs {
namespace {

NodeOptResult run_with(int foldovers, double E) {
  NodeOptResult r;
  r.foldovers_final = foldovers;
  r.E_final = E;
  return r;
}

TEST(RetryRules, AnEmbeddedFinalStateWantsNoRetry) {
  const NodeOptResult ok = run_with(0, 1.0);
  EXPECT_FALSE(fell_back(ok));
  EXPECT_FALSE(unembedded(ok));
  EXPECT_FALSE(wants_keep_apart_retry(ok));
  EXPECT_FALSE(wants_sizing_retry(ok));
  NodeOptResult polish = ok;  // back before the polish: the descent's movement is kept
  polish.polish_reverted = true;
  EXPECT_FALSE(wants_keep_apart_retry(polish));
  EXPECT_FALSE(wants_sizing_retry(polish));
}

TEST(RetryRules, FoldOversOrUntanglingWantBothRetries) {
  NodeOptResult folded = run_with(3, 1.0);
  EXPECT_TRUE(wants_keep_apart_retry(folded));
  EXPECT_TRUE(wants_sizing_retry(folded));
  NodeOptResult untangled = run_with(0, 1.0);
  untangled.untangled = true;
  EXPECT_TRUE(unembedded(untangled));
  EXPECT_TRUE(wants_keep_apart_retry(untangled));
  EXPECT_TRUE(wants_sizing_retry(untangled));
  // A run stopped early (a time limit) is written as it is.
  folded.stopped = untangled.stopped = true;
  EXPECT_FALSE(wants_keep_apart_retry(folded));
  EXPECT_FALSE(wants_sizing_retry(folded));
  EXPECT_FALSE(wants_keep_apart_retry(untangled));
  EXPECT_FALSE(wants_sizing_retry(untangled));
}

TEST(RetryRules, FallbacksWantTheRetriesTheyConcern) {
  NodeOptResult fewest = run_with(0, 1.0);
  fewest.fewest_foldovers_reverted = true;
  EXPECT_TRUE(fell_back(fewest));
  EXPECT_TRUE(wants_keep_apart_retry(fewest));
  EXPECT_FALSE(wants_sizing_retry(fewest)) << "the fewest-fold-over state keeps movement";
  NodeOptResult initial = run_with(0, 7.5);
  initial.initial_reverted = true;
  EXPECT_TRUE(fell_back(initial));
  EXPECT_TRUE(wants_keep_apart_retry(initial));
  EXPECT_TRUE(wants_sizing_retry(initial)) << "the node movement was given up";
}

TEST(RetryRules, KeepApartRetryIsTakenByFoldOversThenUntanglingThenEnergy) {
  const NodeOptResult first = run_with(5, 2.0);
  EXPECT_TRUE(keep_apart_retry_is_better(run_with(4, 9.0), first));
  EXPECT_FALSE(keep_apart_retry_is_better(run_with(6, 0.1), first));
  EXPECT_TRUE(keep_apart_retry_is_better(run_with(5, 1.9), first));
  EXPECT_FALSE(keep_apart_retry_is_better(run_with(5, 2.0), first)) << "a tie keeps the first";
  NodeOptResult untangled_first = run_with(0, 1.0);
  untangled_first.untangled = true;
  EXPECT_TRUE(keep_apart_retry_is_better(run_with(0, 3.0), untangled_first));
  NodeOptResult untangled_run = run_with(0, 0.5);
  untangled_run.untangled = true;
  EXPECT_FALSE(keep_apart_retry_is_better(untangled_run, run_with(0, 1.0)));
}

// The case of the former SizingRetryAfterFallback test: the first run embeds only its initial
// state; a sized run that embeds its moved layout is taken at equal fold-overs although its E
// (with the sizing field) is higher, and one that falls back too is not.
TEST(RetryRules, SizingRetryAfterAFallbackToTheInitialStateIsTakenWhenItKeepsItsMovement) {
  NodeOptResult first = run_with(0, 1.2);
  first.initial_reverted = true;
  ASSERT_TRUE(wants_sizing_retry(first));
  EXPECT_TRUE(sizing_retry_is_better(run_with(0, 7.0), first));
  NodeOptResult back_too = run_with(0, 0.5);
  back_too.initial_reverted = true;
  EXPECT_FALSE(sizing_retry_is_better(back_too, first));
  EXPECT_FALSE(sizing_retry_is_better(run_with(2, 0.5), first)) << "fold-overs come first";
}

TEST(RetryRules, SizingRetryIgnoresTheEnergy) {
  const NodeOptResult first = run_with(3, 2.0);
  EXPECT_TRUE(sizing_retry_is_better(run_with(2, 50.0), first));
  EXPECT_FALSE(sizing_retry_is_better(run_with(3, 0.1), first)) << "E is no criterion";
  EXPECT_FALSE(sizing_retry_is_better(run_with(4, 0.1), first));
  NodeOptResult untangled_first = run_with(0, 1.0);
  untangled_first.untangled = true;
  EXPECT_TRUE(sizing_retry_is_better(run_with(0, 5.0), untangled_first));
  NodeOptResult untangled_run = run_with(0, 1.0);
  untangled_run.untangled = true;
  EXPECT_FALSE(sizing_retry_is_better(untangled_run, untangled_first));
}

}  // namespace
}  // namespace qs
