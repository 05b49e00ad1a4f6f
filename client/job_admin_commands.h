// The CLI's housekeeping commands (`seep delete`, `seep events`) and the --label options of
// `seep submit` and `seep list`.
#pragma once

#include <google/protobuf/map.h>

#include <string>
#include <vector>

#include "commands.h"

namespace seep::client {

// KEY=VALUE options into `out`; returns "" or the error ("--label owner: expected KEY=VALUE",
// "--label a=2: the key 'a' is given twice"). The server checks what keys and values may hold.
std::string ParseLabelOptions(const std::vector<std::string>& options,
                              google::protobuf::Map<std::string, std::string>* out);

// Deletes a finished job with its checkpoints (exit 9 for a queued or running one).
int Delete(const GlobalOptions& global, const std::string& job_id);
// The job's history, oldest first: a TIME / KIND / MESSAGE table, or --json.
int Events(const GlobalOptions& global, const std::string& job_id);

}  // namespace seep::client
