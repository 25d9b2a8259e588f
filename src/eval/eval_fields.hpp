#pragma once
// Internal: the field table of EvaluationConfig (the `evaluation` section).

#include "common/config_fields.hpp"
#include "keyplace/eval/evaluation_config.hpp"

namespace keyplace {

const ConfigFields<EvaluationConfig>& EvaluationConfigFields();

}  // namespace keyplace
