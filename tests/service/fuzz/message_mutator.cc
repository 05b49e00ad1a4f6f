#include "message_mutator.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace seep::fuzz {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

constexpr double kInf = std::numeric_limits<double>::infinity();

std::int64_t OddSigned(std::int64_t current, bool wide, FuzzRandom& random) {
  const std::vector<std::int64_t> values = {0,
                                            1,
                                            -1,
                                            2,
                                            current + 1,
                                            current - 1,
                                            -current,
                                            current * 10,
                                            std::numeric_limits<std::int32_t>::max(),
                                            std::numeric_limits<std::int32_t>::min(),
                                            wide ? std::numeric_limits<std::int64_t>::max() : 1000,
                                            wide ? std::numeric_limits<std::int64_t>::min() : -1000,
                                            wide ? (std::int64_t{1} << 53) + 1 : 65536};
  return random.Pick(values);
}

std::uint64_t OddUnsigned(std::uint64_t current, bool wide, FuzzRandom& random) {
  const std::vector<std::uint64_t> values = {
      0,
      1,
      2,
      current + 1,
      current == 0 ? 0 : current - 1,
      current * 10,
      std::uint64_t{1} << 31,
      std::numeric_limits<std::uint32_t>::max(),
      std::numeric_limits<std::uint32_t>::max() - 1,
      wide ? std::numeric_limits<std::uint64_t>::max() : 1u << 20,
      wide ? std::uint64_t{1} << 63 : 100'000,
      wide ? (std::uint64_t{1} << 53) + 1 : 3};
  return random.Pick(values);
}

std::string OddString(FuzzRandom& random, const MutationLimits& limits) {
  switch (random.Below(9)) {
    case 0:
      return "";
    case 1:
      return std::string(static_cast<std::size_t>(random.Int(200, limits.max_string)), 'x');
    case 2:
      return "evil\n2030-01-01T00:00:00.000 [seepd] info: forged\r\x1b[2J";
    case 3:
      return std::string("nul\0inside", 10);
    case 4:
      return "../../../etc/passwd";
    case 5:
      return "j-0123456789abcdef";
    case 6:
      return "\t \x7f";
    case 7:
      return "%s%n{}{0}";
    default:
      return "ünïcode ☃ 名前";
  }
}

std::string MutateScalar(Message& m, const FieldDescriptor* f, FuzzRandom& random,
                         const MutationLimits& limits) {
  const Reflection* r = m.GetReflection();
  switch (f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE: {
      const double v = OddDouble(r->GetDouble(m, f), random);
      r->SetDouble(&m, f, v);
      return fmt::format("{}", v);
    }
    case FieldDescriptor::CPPTYPE_FLOAT: {
      const auto v = static_cast<float>(OddDouble(r->GetFloat(m, f), random));
      r->SetFloat(&m, f, v);
      return fmt::format("{}", v);
    }
    case FieldDescriptor::CPPTYPE_INT32: {
      const auto v = static_cast<std::int32_t>(OddSigned(r->GetInt32(m, f), false, random));
      r->SetInt32(&m, f, v);
      return fmt::format("{}", v);
    }
    case FieldDescriptor::CPPTYPE_INT64: {
      const std::int64_t v = OddSigned(r->GetInt64(m, f), true, random);
      r->SetInt64(&m, f, v);
      return fmt::format("{}", v);
    }
    case FieldDescriptor::CPPTYPE_UINT32: {
      const auto v = static_cast<std::uint32_t>(OddUnsigned(r->GetUInt32(m, f), false, random));
      r->SetUInt32(&m, f, v);
      return fmt::format("{}", v);
    }
    case FieldDescriptor::CPPTYPE_UINT64: {
      const std::uint64_t v = OddUnsigned(r->GetUInt64(m, f), true, random);
      r->SetUInt64(&m, f, v);
      return fmt::format("{}", v);
    }
    case FieldDescriptor::CPPTYPE_BOOL: {
      const bool v = !r->GetBool(m, f);
      r->SetBool(&m, f, v);
      return v ? "true" : "false";
    }
    case FieldDescriptor::CPPTYPE_ENUM: {
      // An unknown number (proto3 enums are open: it reaches the server as sent), or a known one.
      const int count = f->enum_type()->value_count();
      const std::vector<int> unknown = {-1, count, 99, std::numeric_limits<std::int32_t>::max()};
      const int v = random.Chance(0.5)
                        ? random.Pick(unknown)
                        : f->enum_type()->value(static_cast<int>(random.Below(count)))->number();
      r->SetEnumValue(&m, f, v);
      return fmt::format("{}", v);
    }
    case FieldDescriptor::CPPTYPE_STRING: {
      std::string v = OddString(random, limits);
      const std::string shown = v.size() > 40 ? fmt::format("<{} characters>", v.size()) : v;
      r->SetString(&m, f, std::move(v));
      return fmt::format("\"{}\"", shown);
    }
    case FieldDescriptor::CPPTYPE_MESSAGE:
      break;
  }
  return "?";
}

// Adds `count` elements to repeated scalar field f, each an odd value or a copy of the last.
void GrowRepeatedScalar(Message& m, const FieldDescriptor* f, int count, FuzzRandom& random) {
  const Reflection* r = m.GetReflection();
  for (int i = 0; i < count; ++i) {
    switch (f->cpp_type()) {
      case FieldDescriptor::CPPTYPE_DOUBLE:
        r->AddDouble(&m, f, i % 1000 == 0 ? OddDouble(1.0, random) : 1e-3 * (i % 97));
        break;
      case FieldDescriptor::CPPTYPE_FLOAT:
        r->AddFloat(&m, f, 1.0F);
        break;
      case FieldDescriptor::CPPTYPE_INT32:
        r->AddInt32(&m, f, i);
        break;
      case FieldDescriptor::CPPTYPE_INT64:
        r->AddInt64(&m, f, i);
        break;
      case FieldDescriptor::CPPTYPE_UINT32:
        r->AddUInt32(&m, f, static_cast<std::uint32_t>(i));
        break;
      case FieldDescriptor::CPPTYPE_UINT64:
        r->AddUInt64(&m, f, static_cast<std::uint64_t>(i));
        break;
      case FieldDescriptor::CPPTYPE_BOOL:
        r->AddBool(&m, f, i % 2 == 0);
        break;
      case FieldDescriptor::CPPTYPE_ENUM:
        r->AddEnumValue(&m, f, i % 7);
        break;
      case FieldDescriptor::CPPTYPE_STRING:
        r->AddString(&m, f, fmt::format("s{}", i));
        break;
      case FieldDescriptor::CPPTYPE_MESSAGE:
        break;
    }
  }
}

// One element of repeated scalar field f set to an odd value (through a temporary message
// holding the element, so that MutateScalar's cases serve both kinds of field).
std::string MutateRepeatedScalar(Message& m, const FieldDescriptor* f, FuzzRandom& random,
                                 const MutationLimits& limits) {
  const Reflection* r = m.GetReflection();
  const int size = r->FieldSize(m, f);
  const std::uint64_t choice = random.Below(size > 0 ? 5 : 2);
  if (choice == 0) {
    const int count =
        random.Chance(0.2) ? random.Int(1000, limits.max_repeated) : random.Int(1, 20);
    GrowRepeatedScalar(m, f, count, random);
    return fmt::format("{} elements added (now {})", count, size + count);
  }
  if (choice == 1) {
    r->ClearField(&m, f);
    return "cleared";
  }
  if (choice == 2) {
    r->RemoveLast(&m, f);
    return "last removed";
  }
  const int index = static_cast<int>(random.Below(size));
  switch (f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE: {
      const double v = OddDouble(r->GetRepeatedDouble(m, f, index), random);
      r->SetRepeatedDouble(&m, f, index, v);
      return fmt::format("[{}] = {}", index, v);
    }
    case FieldDescriptor::CPPTYPE_UINT64: {
      const std::uint64_t v = OddUnsigned(r->GetRepeatedUInt64(m, f, index), true, random);
      r->SetRepeatedUInt64(&m, f, index, v);
      return fmt::format("[{}] = {}", index, v);
    }
    case FieldDescriptor::CPPTYPE_STRING: {
      const std::string v = OddString(random, limits);
      r->SetRepeatedString(&m, f, index, v);
      return fmt::format("[{}] = <{} characters>", index, v.size());
    }
    case FieldDescriptor::CPPTYPE_ENUM: {
      const int v = random.Chance(0.5) ? 99 : -1;
      r->SetRepeatedEnumValue(&m, f, index, v);
      return fmt::format("[{}] = {}", index, v);
    }
    default: {
      GrowRepeatedScalar(m, f, 1, random);
      r->SwapElements(&m, f, index, size);
      return fmt::format("[{}] replaced", index);
    }
  }
}

const FieldDescriptor* PickField(const Message& m, FuzzRandom& random) {
  const auto* d = m.GetDescriptor();
  if (d->field_count() == 0) return nullptr;
  // Mostly a field that is set: that is where a valid request's meaning is.
  std::vector<const FieldDescriptor*> set;
  m.GetReflection()->ListFields(m, &set);
  if (!set.empty() && random.Chance(0.75)) return set[random.Below(set.size())];
  return d->field(static_cast<int>(random.Below(d->field_count())));
}

std::string MutateIn(Message& m, const std::string& path, FuzzRandom& random,
                     const MutationLimits& limits, int depth) {
  const FieldDescriptor* f = PickField(m, random);
  if (f == nullptr) return path + ": nothing to mutate";
  const Reflection* r = m.GetReflection();
  const std::string here = path.empty() ? f->name() : path + "." + f->name();
  if (f->is_repeated() && f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
    const int size = r->FieldSize(m, f);
    const std::uint64_t choice = random.Below(10);
    if (size > 0 && choice < 6 && depth < 12) {
      const int index = static_cast<int>(random.Below(size));
      return MutateIn(*r->MutableRepeatedMessage(&m, f, index), fmt::format("{}[{}]", here, index),
                      random, limits, depth + 1);
    }
    if (choice < 8) {
      // Empty elements, or copies of one (huge repeated messages: effects, stages, regions).
      const int count = random.Chance(0.3) ? random.Int(100, 20'000) : random.Int(1, 4);
      const bool copy = size > 0 && random.Chance(0.5);
      for (int i = 0; i < count; ++i) {
        Message* added = r->AddMessage(&m, f);
        if (copy) added->CopyFrom(r->GetRepeatedMessage(m, f, 0));
      }
      return fmt::format("{}: {} {} added", here, count, copy ? "copies" : "empty elements");
    }
    r->ClearField(&m, f);
    return here + ": cleared";
  }
  if (f->is_repeated()) return here + ": " + MutateRepeatedScalar(m, f, random, limits);
  if (f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
    const std::uint64_t choice = random.Below(10);
    if (choice < 7 && depth < 12) {
      return MutateIn(*r->MutableMessage(&m, f), here, random, limits, depth + 1);
    }
    if (choice < 9) {
      r->MutableMessage(&m, f)->Clear();
      return here + ": set, empty";
    }
    r->ClearField(&m, f);
    return here + ": cleared";
  }
  return here + " = " + MutateScalar(m, f, random, limits);
}

}  // namespace

double OddDouble(double current, FuzzRandom& random) {
  switch (random.Below(14)) {
    case 0:
      return 0.0;
    case 1:
      return -0.0;
    case 2:
      return -current;
    case 3:
      return std::numeric_limits<double>::quiet_NaN();
    case 4:
      return kInf;
    case 5:
      return -kInf;
    case 6:
      return 1e300;
    case 7:
      return -1e300;
    case 8:
      return 1e-300;
    case 9:
      return std::numeric_limits<double>::denorm_min();
    case 10:
      return std::numeric_limits<double>::max();
    case 11:
      return -1.0;
    default:
      // Near the valid value: a power of ten either way, where limits are most often missed.
      return current * std::pow(10.0, random.Int(-6, 6));
  }
}

std::string MutateOnce(google::protobuf::Message& message, const std::string& root,
                       FuzzRandom& random, const MutationLimits& limits) {
  return MutateIn(message, root, random, limits, 0);
}

}  // namespace seep::fuzz
