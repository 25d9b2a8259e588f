// Reads a log through the installed library and prints its scan count.
#include <iostream>

#include "keyplace/io/carmen_log.hpp"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const keyplace::CarmenLog log = keyplace::ReadCarmenLog(argv[1]);
  std::cout << log.scans.size() << "\n";
  return log.scans.empty() ? 1 : 0;
}
