#pragma once
// What a resumed run may not change in the database it continues (DatabaseWriter::resume).
#include <string>

#include "store/manifest.hpp"

namespace panoptes::store {

/// The first difference between the manifest a database was written with (`old`) and the one a run
/// that resumes it brings (`now`) that would make the continued movies a different dataset: grid
/// (domain), image size, video settings, movie pattern, rig, cameras, navigation graph, parameter axes
/// or tasks. One phrase naming the part and both values, e.g. `the grid differs (dims [32,32,32] in
/// the database, [64,32,32] in this run)`; empty when they agree. Title, provenance and times may differ.
std::string resume_mismatch(const Manifest& old, const Manifest& now);

}  // namespace panoptes::store
