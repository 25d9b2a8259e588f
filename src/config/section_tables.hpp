#pragma once
// Internal: every module's field tables, each declared in its module (src/<module>/*_fields.hpp)
// and defined beside its struct, composed into the whole configuration in config.cpp.

#include "eval/eval_fields.hpp"
#include "features/features_fields.hpp"
#include "io/io_fields.hpp"
#include "localization/localization_fields.hpp"
#include "mapping/mapping_fields.hpp"
#include "place/place_fields.hpp"
#include "registration/registration_fields.hpp"
#include "slam/slam_fields.hpp"
