// The read model's text of numbers and times (introspect/format.hpp), which every tool prints.

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "safecass/introspect/format.hpp"

namespace safecass::introspect {
namespace {

TEST(SecondsText, HasSixDecimalsAsInTheHistoryFile) {
  EXPECT_EQ(seconds_text(Time{std::chrono::seconds(12)}), "12.000000");
  EXPECT_EQ(seconds_text(Time{std::chrono::microseconds(301000)}), "0.301000");
}

TEST(NumberText, HasAtMostNineSignificantDigitsAndNamesNonFiniteValues) {
  EXPECT_EQ(number_text(30.0), "30");
  EXPECT_EQ(number_text(1.0 / 3.0), "0.333333333");
  EXPECT_EQ(number_text(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(number_text(-std::numeric_limits<double>::infinity()), "-inf");
}

TEST(MarkupText, EscapesTheFiveMarkupCharactersAndCopiesEveryOtherByte) {
  EXPECT_EQ(markup_text("a<b>&\"c'd"), "a&lt;b&gt;&amp;&quot;c&#39;d");
  EXPECT_EQ(markup_text("JR3.s_A \xc2\xb0 \n"), "JR3.s_A \xc2\xb0 \n");
  EXPECT_EQ(markup_text(""), "");
}

}  // namespace
}  // namespace safecass::introspect
