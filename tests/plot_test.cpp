// The experiments' OpenCV plots (experiments/plot.*): round ticks, titles that fit.
#include <gtest/gtest.h>

#include "experiments/plot.hpp"

using namespace omniloc::experiments;

TEST(Plot, TicksAreRoundAndCoverTheData) {
  // The report showed ticks at 734 / 587 / 440 (a fifth of the data's range each).
  EXPECT_EQ(nice_ticks(440, 734), (std::vector<double>{400, 450, 500, 550, 600, 650, 700, 750}));
  EXPECT_EQ(nice_ticks(0, 1, 5), (std::vector<double>{0, 0.2, 0.4, 0.6000000000000001, 0.8, 1}));
  EXPECT_EQ(nice_ticks(0, 0.37, 5), (std::vector<double>{0, 0.1, 0.2, 0.30000000000000004, 0.4}));
  EXPECT_EQ(nice_ticks(-3, 7, 5), (std::vector<double>{-4, -2, 0, 2, 4, 6, 8}));
  EXPECT_EQ(nice_ticks(1, 3, 6, true), (std::vector<double>{1, 2, 3}));  // integer data: whole steps
  const std::vector<double> t = nice_ticks(0.0123, 0.0456, 6);
  EXPECT_LE(t.front(), 0.0123);
  EXPECT_GE(t.back(), 0.0456);
  EXPECT_LE(t.size(), 7u);
}

TEST(Plot, ALongTitleShrinksInsteadOfRunningOffTheImage) {
  const std::string title = "Position error of the two-circle solver against the three-point solver over the field, 2 px noise (cm)";
  const cv::Mat m = line_plot({{"a", {0, 1, 2}, {1, 4, 9}}}, title, "x", "y");
  // The rightmost 6 columns of the title band stay white: the text ended inside the image.
  const cv::Mat band = m(cv::Rect(m.cols - 6, 0, 6, 30));
  EXPECT_EQ(cv::countNonZero(band.reshape(1) != 255), 0);
}
