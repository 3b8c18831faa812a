// Small builders shared by the report's figures (internal to lib/report).
#pragma once

#include <string>
#include <utility>

#include "navimpact/plot/figure.hpp"

namespace navimpact::report::detail {

/// A figure of @p rows x @p cols panels, @p width x @p height pixels, with its title.
inline plot::Figure figureOf(int width, int height, std::string title, int rows = 1, int cols = 1) {
  plot::Figure fig;
  fig.width = width;
  fig.height = height;
  fig.rows = rows;
  fig.cols = cols;
  fig.title = std::move(title);
  return fig;
}

/// A panel with log10 x and y axes and their labels.
inline plot::Axes logLogAxes(std::string xlabel, std::string ylabel) {
  plot::Axes ax;
  ax.xlabel = std::move(xlabel);
  ax.ylabel = std::move(ylabel);
  ax.logx = ax.logy = true;
  return ax;
}

}  // namespace navimpact::report::detail
