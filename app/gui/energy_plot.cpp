#include "app/gui/energy_plot.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "app/gui/plot_ticks.h"

namespace qs::app {

void draw_energy_plot(const std::vector<double>& energy, int marked, float width_px, float height) {
  std::vector<std::pair<int, double>> points;  // (step, E)
  for (int k = 0; k < int(energy.size()); ++k)
    if (std::isfinite(energy[k]) && energy[k] > 0.0) points.push_back({k + 1, energy[k]});
  if (points.size() < 2) return;
  double lo = points[0].second, hi = lo;
  for (const auto& p : points) lo = std::min(lo, p.second), hi = std::max(hi, p.second);
  if (hi <= lo * (1 + 1e-12)) lo *= 0.9, hi *= 1.1;
  const std::vector<AxisTick> y_ticks = log_ticks(lo, hi);
  lo = std::min(lo, y_ticks.front().value);
  hi = std::max(hi, y_ticks.back().value);
  const double log_lo = std::log10(lo), log_hi = std::log10(hi);
  const int first = points.front().first, last = points.back().first;

  ImDrawList* draw = ImGui::GetWindowDrawList();
  const float text_h = ImGui::GetTextLineHeight();
  float label_w = 0.0f;
  for (const auto& t : y_ticks) label_w = std::max(label_w, ImGui::CalcTextSize(t.label.c_str()).x);
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float width = std::max(80.0f, width_px);
  ImGui::InvisibleButton("##energy_plot", ImVec2(width, height));
  const bool hovered = ImGui::IsItemHovered();
  // Plot area: labels left of it and below it, half a line of room at the top.
  const ImVec2 p0(origin.x + label_w + 6.0f, origin.y + 0.5f * text_h);
  const ImVec2 p1(origin.x + width - 4.0f, origin.y + height - text_h - 4.0f);
  if (p1.x <= p0.x + 10.0f || p1.y <= p0.y + 10.0f) return;
  const auto x_of = [&](double step) {
    return last > first ? p0.x + float((step - first) / double(last - first)) * (p1.x - p0.x)
                        : 0.5f * (p0.x + p1.x);
  };
  const auto y_of = [&](double e) {
    const double t = log_hi > log_lo ? (std::log10(e) - log_lo) / (log_hi - log_lo) : 0.5;
    return p1.y - float(t) * (p1.y - p0.y);
  };
  const ImU32 frame = ImGui::GetColorU32(ImGuiCol_FrameBg);
  const ImU32 grid = IM_COL32(255, 255, 255, 28);
  const ImU32 text = ImGui::GetColorU32(ImGuiCol_TextDisabled);
  draw->AddRectFilled(p0, p1, frame);
  for (const auto& t : y_ticks) {
    const float y = y_of(t.value);
    draw->AddLine(ImVec2(p0.x, y), ImVec2(p1.x, y), grid);
    const float w = ImGui::CalcTextSize(t.label.c_str()).x;
    draw->AddText(ImVec2(p0.x - 4.0f - w, y - 0.5f * text_h), text, t.label.c_str());
  }
  const int max_x_ticks = std::max(2, int((p1.x - p0.x) / (3.5f * text_h)));
  for (const auto& t : step_ticks(first, last, max_x_ticks)) {
    const float x = x_of(t.value);
    draw->AddLine(ImVec2(x, p0.y), ImVec2(x, p1.y), grid);
    const float w = ImGui::CalcTextSize(t.label.c_str()).x;
    const float left = std::clamp(x - 0.5f * w, p0.x - 4.0f, p1.x - w + 4.0f);
    draw->AddText(ImVec2(left, p1.y + 2.0f), text, t.label.c_str());
  }
  if (marked >= 0 && marked + 1 >= first && marked + 1 <= last) {
    const float x = x_of(marked + 1);
    draw->AddLine(ImVec2(x, p0.y), ImVec2(x, p1.y), IM_COL32(13, 217, 242, 160), 1.5f);
  }
  std::vector<ImVec2> line;
  for (const auto& [step, e] : points) line.emplace_back(x_of(step), y_of(e));
  draw->AddPolyline(line.data(), int(line.size()), ImGui::GetColorU32(ImGuiCol_PlotLines), 0, 1.5f);
  if (hovered) {
    // The step nearest to the cursor.
    const float mx = ImGui::GetIO().MousePos.x;
    const auto nearest = std::min_element(points.begin(), points.end(), [&](auto& a, auto& b) {
      return std::abs(x_of(a.first) - mx) < std::abs(x_of(b.first) - mx);
    });
    draw->AddCircleFilled(ImVec2(x_of(nearest->first), y_of(nearest->second)), 3.0f,
                          ImGui::GetColorU32(ImGuiCol_PlotLinesHovered));
    ImGui::SetTooltip("step %d: E = %.6g\n(x: step, y: energy E, log scale)", nearest->first,
                      nearest->second);
  }
}

}  // namespace qs::app
