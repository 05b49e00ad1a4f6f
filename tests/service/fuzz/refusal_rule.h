// When a refusal names what it refuses, checkably. INVALID_ARGUMENT and OUT_OF_RANGE start with
// a path of the request's own fields ("scene.packing.lattice.columns: ...", "labels[\"K\"]: ...",
// "sweep.axes[0].numbers[2]: ..."), every name a field (or a oneof) of the message the path has
// reached in the request's descriptor, indices allowed on any step; or with "<Method>: the
// request's bytes do not decode", for bytes that are no request at all. NOT_FOUND and
// FAILED_PRECONDITION name the field the same way or hold the id the request sent.
// RESOURCE_EXHAUSTED says which limit (non-empty). Every other code is no refusal of the
// request but a failure of the service. ALREADY_EXISTS (a request_id used before for another
// request) names its field as INVALID_ARGUMENT does.
#pragma once

#include <google/protobuf/descriptor.h>
#include <grpcpp/support/status.h>

#include <string>

namespace seep::fuzz {

// The leading field path of `message` resolved in `request`: "" when it resolves, else why not.
std::string FieldPathProblem(const google::protobuf::Descriptor& request,
                             const std::string& message);

// "" when the refusal of a `method` call carrying `id` (the request's id field, "" when none)
// is one a client can act on by the rule above; else what is wrong with it.
std::string RefusalProblem(const google::protobuf::Descriptor& request, const std::string& method,
                           const std::string& id, const grpc::Status& status);

}  // namespace seep::fuzz
