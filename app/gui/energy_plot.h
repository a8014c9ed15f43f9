// The convergence plot of the Pipeline panel (ImGui): the energy per step, step on the x
// axis, E on a log10 y axis, both with tick labels; hovering shows a step's value.
#pragma once

#include <vector>

namespace qs::app {

//! Draws the plot of \p energy (value k: step k + 1; non-finite or non-positive values are
//! skipped), \p width x \p height pixels; \p marked (index, -1: none) is marked with a vertical
//! line (the scrubbed step).
void draw_energy_plot(const std::vector<double>& energy, int marked, float width, float height);

}  // namespace qs::app
