// The names of the values of the simplifier's enums (qem/simplify.h), each written once: to_string,
// from_string and option_names read the same table, and the command line offers and parses its
// choices through them.
#include <span>
#include <string>
#include <vector>

#include "qem/simplify.h"

namespace qem {

namespace {

template <class Enum>
struct Named {
  Enum value;
  const char* name;
};

constexpr Named<Weighting> kWeighting[] = {
    {Weighting::Area, "area"}, {Weighting::Uniform, "uniform"}, {Weighting::Angle, "angle"}};
constexpr Named<Placement> kPlacement[] = {{Placement::Optimal, "optimal"},
                                           {Placement::Segment, "segment"},
                                           {Placement::Midpoint, "midpoint"},
                                           {Placement::Endpoints, "endpoints"}};
constexpr Named<Scheme> kScheme[] = {{Scheme::Greedy, "greedy"}, {Scheme::Passes, "passes"}};
// Ignore is "off" on the command line: inversions are then not checked at all.
constexpr Named<InversionPolicy> kInversion[] = {{InversionPolicy::Forbid, "forbid"},
                                                 {InversionPolicy::Penalize, "penalize"},
                                                 {InversionPolicy::Ignore, "off"}};
constexpr Named<TwoSided> kTwoSided[] = {{TwoSided::Rims, "rims"}, {TwoSided::All, "all"}, {TwoSided::None, "none"}};
constexpr Named<SeamMode> kSeamMode[] = {{SeamMode::Junctions, "junctions"},
                                         {SeamMode::Strict, "strict"},
                                         {SeamMode::Creases, "creases"},
                                         {SeamMode::Permissive, "permissive"}};
// Stop reasons are reported, never parsed: their names are phrases.
constexpr Named<StopReason> kStopReason[] = {
    {StopReason::TargetReached, "target reached"},
    {StopReason::ErrorLimit, "error limit reached"},
    {StopReason::NoValidPair, "no valid contraction left"},
    {StopReason::AlreadyBelowTarget, "input already at or below target"},
    {StopReason::Cancelled, "cancelled"}};

// The table of an enum, chosen by the type of the (unused) argument.
std::span<const Named<Weighting>> table(Weighting) { return kWeighting; }
std::span<const Named<Placement>> table(Placement) { return kPlacement; }
std::span<const Named<Scheme>> table(Scheme) { return kScheme; }
std::span<const Named<InversionPolicy>> table(InversionPolicy) { return kInversion; }
std::span<const Named<TwoSided>> table(TwoSided) { return kTwoSided; }
std::span<const Named<SeamMode>> table(SeamMode) { return kSeamMode; }
std::span<const Named<StopReason>> table(StopReason) { return kStopReason; }

template <class Enum>
const char* name_of(Enum value) {
  for (const Named<Enum>& e : table(value))
    if (e.value == value) return e.name;
  return "?";  // a value cast from an integer outside the enum
}

template <class Enum>
bool value_of(const std::string& name, Enum& out) {
  for (const Named<Enum>& e : table(out))
    if (name == e.name) {
      out = e.value;
      return true;
    }
  return false;
}

}  // namespace

const char* to_string(StopReason reason) { return name_of(reason); }
const char* to_string(Weighting w) { return name_of(w); }
const char* to_string(Placement p) { return name_of(p); }
const char* to_string(Scheme s) { return name_of(s); }
const char* to_string(InversionPolicy policy) { return name_of(policy); }
const char* to_string(TwoSided t) { return name_of(t); }
const char* to_string(SeamMode s) { return name_of(s); }

bool from_string(const std::string& name, Weighting& out) { return value_of(name, out); }
bool from_string(const std::string& name, Placement& out) { return value_of(name, out); }
bool from_string(const std::string& name, Scheme& out) { return value_of(name, out); }
bool from_string(const std::string& name, InversionPolicy& out) { return value_of(name, out); }
bool from_string(const std::string& name, TwoSided& out) { return value_of(name, out); }
bool from_string(const std::string& name, SeamMode& out) { return value_of(name, out); }

template <class Enum>
std::vector<std::string> option_names() {
  std::vector<std::string> out;
  for (const Named<Enum>& e : table(Enum{})) out.emplace_back(e.name);
  return out;
}
template std::vector<std::string> option_names<Weighting>();
template std::vector<std::string> option_names<Placement>();
template std::vector<std::string> option_names<Scheme>();
template std::vector<std::string> option_names<InversionPolicy>();
template std::vector<std::string> option_names<TwoSided>();
template std::vector<std::string> option_names<SeamMode>();

}  // namespace qem
