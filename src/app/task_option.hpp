#pragma once
// `--task` of the playback commands: a task index or a task name ("p+s"), as scripts' `task=` take it.
#include <cstdlib>
#include <string>

#include "core/error.hpp"
#include "store/database.hpp"

namespace panoptes::app {

/// The index of the task `value` names in the database `db` (an index "2" or a name "p+s"); throws
/// panoptes::Error naming the option, the value and the database's tasks if there is none.
inline int resolve_task_option(const std::string& db, const std::string& value) {
  const store::Database database = store::Database::open(db);
  const store::Manifest& m = database.manifest();
  char* end = nullptr;
  const long index = std::strtol(value.c_str(), &end, 10);
  if (!value.empty() && *end == '\0' && index >= 0 && index < long(m.tasks.size())) return int(index);
  const int named = m.find_task(value);
  if (named >= 0) return named;
  std::string names;
  for (const auto& t : m.tasks) names += (names.empty() ? "" : ", ") + t.name;
  throw Error("--task \"" + value + "\": " + db + " has no such task; expected an index 0.." +
              std::to_string(m.tasks.size() - 1) + " or a name (" + names + ")");
}

}  // namespace panoptes::app
