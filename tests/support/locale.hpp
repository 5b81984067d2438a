// Test helper: sets a C locale whose decimal separator is a comma for a scope (the C library's strtod
// then reads "0,5" and rejects "0.5"), so text readers can be checked to ignore the global locale.
// Not a paper equation; restores the previous locale on destruction.
#pragma once

#include <clocale>
#include <string>

namespace dyncull::test {

// Tries a few common comma-decimal locales; active() is false when none is installed (callers GTEST_SKIP).
class CommaDecimalLocale {
 public:
  CommaDecimalLocale() {
    const char* saved = std::setlocale(LC_ALL, nullptr);
    saved_ = saved ? saved : "C";
    for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "de_DE", "fr_FR.UTF-8", "nl_NL.UTF-8"}) {
      if (std::setlocale(LC_ALL, name) && std::localeconv()->decimal_point[0] == ',') {
        active_ = true;
        return;
      }
    }
    std::setlocale(LC_ALL, saved_.c_str());
  }
  ~CommaDecimalLocale() { std::setlocale(LC_ALL, saved_.c_str()); }
  CommaDecimalLocale(const CommaDecimalLocale&) = delete;
  CommaDecimalLocale& operator=(const CommaDecimalLocale&) = delete;
  bool active() const { return active_; }

 private:
  std::string saved_;
  bool active_ = false;
};

}  // namespace dyncull::test
