#include "keyplace/config/log_inputs.hpp"

namespace keyplace {

LogInputOptions LogInputOptionsFor(const Config& config) {
  LogInputOptions options;
  options.reading.bag = config.input;
  options.odometry = config.odometry;
  options.features = config.features;
  return options;
}

}  // namespace keyplace
