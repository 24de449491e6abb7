#include "daemon/comms/item_assembler.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

const std::string kPayload = "0123456789abcdefghijklmnopqrstuvwxyz";

ItemAssembler::Outcome AddPiece(ItemAssembler& a, uint64_t seq, uint32_t offset, size_t size, uint32_t crc = 7) {
  const std::string data = kPayload.substr(offset, size);
  return a.Add({"rover1", 1, seq}, {9, crc, static_cast<uint32_t>(kPayload.size()), offset, &data});
}

TEST(ItemAssemblerTest, PiecesInAnyOrderWithRepeatsAndOverlaps) {
  ItemAssembler a(1000);
  EXPECT_FALSE(AddPiece(a, 1, 20, 16).complete);
  EXPECT_FALSE(AddPiece(a, 1, 20, 16).complete);  // a repeat costs nothing
  EXPECT_EQ(a.bytes(), 16u);
  EXPECT_TRUE(a.Prefixes().empty());  // nothing from the start yet
  EXPECT_FALSE(AddPiece(a, 1, 0, 8).complete);
  ASSERT_EQ(a.Prefixes().size(), 1u);
  EXPECT_EQ(a.Prefixes()[0].second, 8u);
  // Cut differently by another sender: overlapping, and longer at an offset already held.
  EXPECT_FALSE(AddPiece(a, 1, 4, 10).complete);
  EXPECT_EQ(a.Prefixes()[0].second, 14u);
  EXPECT_FALSE(AddPiece(a, 1, 0, 12).complete);
  const ItemAssembler::Outcome out = AddPiece(a, 1, 12, 9);
  ASSERT_TRUE(out.complete);
  EXPECT_EQ(out.payload, kPayload);
  EXPECT_EQ(out.kind, 9);
  EXPECT_EQ(out.crc, 7u);
  EXPECT_EQ(a.bytes(), 0u);
  EXPECT_EQ(a.items(), 0u);
}

TEST(ItemAssemblerTest, AnotherVersionReplacesTheHeldPieces) {
  ItemAssembler a(1000);
  AddPiece(a, 1, 0, 10, 7);
  const ItemAssembler::Outcome out = AddPiece(a, 1, 10, 10, 8);
  EXPECT_TRUE(out.conflict);
  EXPECT_FALSE(out.complete);
  ASSERT_EQ(a.items(), 1u);
  EXPECT_EQ(a.bytes(), 10u);
  EXPECT_TRUE(a.Prefixes().empty());  // only the new version's piece at 10 is held
}

TEST(ItemAssemblerTest, ANewItemBeyondTheBoundIsDropped) {
  ItemAssembler a(20);
  AddPiece(a, 1, 0, 16);
  EXPECT_TRUE(AddPiece(a, 2, 0, 8).full);
  EXPECT_EQ(a.items(), 1u);
  // Pieces of an item already held still count against the bound, but are taken.
  EXPECT_FALSE(AddPiece(a, 1, 16, 8).full);
  EXPECT_EQ(a.bytes(), 24u);
  const auto prefixes = a.Prefixes();
  ASSERT_EQ(prefixes.size(), 1u);
  EXPECT_EQ(std::get<2>(prefixes[0].first), 1u);
  EXPECT_EQ(prefixes[0].second, 24u);
}

}  // namespace
}  // namespace cairn
