/// makeStrategy and the list of strategies (estimator/core/strategy_list.h): every listed name
/// builds a strategy of that name, an unlisted one is refused by the options and the factory.
#include <gtest/gtest.h>

#include <stdexcept>

#include "estimator/core/strategy_list.h"
#include "estimator/filter/strategy_factory.h"

using namespace meshnav::estimator;

TEST(StrategyFactory, EveryListedStrategyIsBuiltUnderItsName) {
  ASSERT_FALSE(kStrategyList.empty());
  for (const auto& entry : kStrategyList) {
    EstimatorOptions o;
    o.strategy = std::string(entry.name);
    EXPECT_NO_THROW(o.validate()) << entry.name;
    EXPECT_TRUE(strategyListed(o.strategy));
    const auto s = makeStrategy(o);
    ASSERT_NE(s, nullptr) << entry.name;
    EXPECT_EQ(s->name(), entry.name);
    EXPECT_EQ(s->clone()->name(), entry.name);
  }
}

TEST(StrategyFactory, UnlistedNamesAreRefusedEverywhere) {
  EstimatorOptions o;
  o.strategy = "ukf";
  EXPECT_FALSE(strategyListed(o.strategy));
  try {
    o.validate();
    FAIL() << "an unlisted strategy passed validation";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("strategy must be one of " + strategyNames(", ")), std::string::npos) << e.what();
  }
  EXPECT_THROW(makeStrategy(o), std::invalid_argument);
  EXPECT_EQ(strategyNames().substr(0, 18), "centralized|dp|dah");  // the first three, in this order
}
