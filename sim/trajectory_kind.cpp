#include "sim/trajectory_kind.h"

#include "sim/enum_names.h"

namespace meshnav::sim {

namespace {
constexpr EnumNameTable<TrajectoryKind, 6> kNames{{{TrajectoryKind::Spiral, "spiral"},
                                                   {TrajectoryKind::Figure8, "figure8"},
                                                   {TrajectoryKind::Lawnmower, "lawnmower"},
                                                   {TrajectoryKind::Helix, "helix"},
                                                   {TrajectoryKind::Hover, "hover"},
                                                   {TrajectoryKind::Walk, "walk"}}};
}  // namespace

std::string toString(TrajectoryKind kind) { return enumName(kNames, kind); }
std::optional<TrajectoryKind> parseTrajectoryKind(std::string_view name) { return parseEnumName(kNames, name); }
std::string trajectoryKindNames() { return enumNameList(kNames); }

}  // namespace meshnav::sim
