// SPDX-License-Identifier: MIT
#pragma once

// What `hrg study tolerance` writes: one JSON line per point (what a
// distributed run's workers print and what the local run writes too), and
// study.json gathering the lines of every point in index order. The CSV and
// the plots are made from study.json by tools/study/study_report.py, so a
// local and a distributed run give the same files.

#include <filesystem>
#include <string>
#include <vector>

#include "study/grid.hpp"
#include "study/point.hpp"

namespace hrg::study {

// The point as one line of JSON (no newline); nothing in it depends on the
// machine, the thread count or the time of day.
std::string point_json_line(const PointResult& p);

// The point index a line starts with ({"point": K, ...}); throws
// std::runtime_error naming `where` for anything else.
std::size_t point_index_of_line(const std::string& line, const std::string& where);

// Reads a file of point lines (one per point, any order) and returns them in
// index order. Throws std::runtime_error naming file:line for a malformed
// line, a duplicate, a point outside the grid or a missing point.
std::vector<std::string> read_point_lines(const std::string& path, const Grid& grid);

// DIR/study.json: the grid's run settings and the point lines in index order.
void write_study_json(const std::filesystem::path& dir, const Grid& grid,
                      const std::vector<std::string>& lines);

}  // namespace hrg::study
