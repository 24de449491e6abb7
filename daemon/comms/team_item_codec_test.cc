#include "daemon/comms/team_item_codec.h"

#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "cairn/exchange.pb.h"
#include "mapping/testing/submap_test_util.h"

namespace cairn {
namespace {

TeamItemCodec::Names TestNames() {
  TeamItemCodec::Names n;
  n.letter_of = [](const std::string& r) { return r == "rover1" ? 'a' : r == "hexa" ? 'b' : char{0}; };
  n.frame_index = [](const std::string&, uint32_t incarnation, uint64_t frame) {
    return (static_cast<uint64_t>(incarnation) << 40) | frame;
  };
  return n;
}

StoreItem Item(const std::string& origin, TeamItemKind kind, std::string payload) {
  StoreItem item;
  item.key = ItemKey{origin, LaneOf(kind), 1};
  item.kind = static_cast<uint16_t>(kind);
  item.payload = std::move(payload);
  return item;
}

FrameSwitchEvent Switch() {
  FrameSwitchEvent e;
  e.time = Timestamp::FromSeconds(12.5);
  e.old_frame_id = 3;
  e.new_frame_id = 4;
  e.transform.T_old_new.translation() = Eigen::Vector3d(6.5, -0.25, 0.1);
  e.transform.T_old_new.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  e.transform.covariance = Matrix6d::Identity() * 0.01;
  e.transform.covariance(0, 1) = e.transform.covariance(1, 0) = 0.002;
  return e;
}

TEST(TeamItemCodecTest, FrameSwitchRoundTripsWithItsRun) {
  const FrameSwitchEvent e = Switch();
  auto in = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kFrameSwitch, TeamItemCodec::FrameSwitch(2, e)), TestNames());
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  EXPECT_EQ(in->kind, TeamInput::Kind::kFrameSwitch);
  EXPECT_EQ(in->letter, 'b');
  EXPECT_EQ(in->old_frame, (uint64_t{2} << 40) | 3);
  EXPECT_EQ(in->new_frame, (uint64_t{2} << 40) | 4);
  EXPECT_TRUE(in->T_old_new.isApprox(e.transform.T_old_new, 1e-12));
  EXPECT_TRUE(in->switch_covariance.isApprox(e.transform.covariance, 1e-15));
}

TEST(TeamItemCodecTest, PoseBatchKeepsTrajectoryAndGraphPoses) {
  std::vector<OwnEstimate> batch(3);
  for (int i = 0; i < 3; ++i) {
    batch[i].estimate.time = Timestamp::FromSeconds(1.0 + i);
    batch[i].estimate.frame_id = 7;
    batch[i].estimate.T_frame_body.translation() = Eigen::Vector3d(i, 2 * i, 0.5);
    batch[i].estimate.pose_covariance = Matrix6d::Identity() * (i + 1) * 1e-4;
  }
  batch[1].graph_pose = true;
  batch[1].pose_index = 42;
  auto in = TeamItemCodec::Decode(Item("rover1", TeamItemKind::kPoseBatch, TeamItemCodec::PoseBatch(2, batch)), TestNames());
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  ASSERT_EQ(in->poses.size(), 3u);
  ASSERT_EQ(in->graph_poses.size(), 1u);
  // Pose indices carry the run as frames do: a restarted robot counts its poses from 0 again.
  EXPECT_EQ(in->graph_poses[0].pose_index, (uint64_t{2} << 40) | 42);
  EXPECT_NEAR(in->poses[2].T_frame_body.translation().y(), 4.0, 1e-6);
  EXPECT_EQ(in->poses[2].frame, (uint64_t{2} << 40) | 7);
  EXPECT_NEAR(in->graph_poses[0].covariance(3, 3), 2e-4, 1e-12);
}

TEST(TeamItemCodecTest, SubmapTravelsInItsWireFormat) {
  const auto submap = testing::SyntheticSubmap(5);
  auto payload = TeamItemCodec::Submap(0, *submap);
  ASSERT_TRUE(payload.ok());
  auto in = TeamItemCodec::Decode(Item("rover1", TeamItemKind::kSubmap, *payload), TestNames());
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  EXPECT_EQ(in->new_frame, 5u);
  EXPECT_EQ(in->submap->points().size(), submap->points().size());
  // A submap under another robot's name is refused.
  auto lie = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kSubmap, *payload), TestNames());
  ASSERT_FALSE(lie.ok());
  EXPECT_NE(lie.status().ToString().find("hexa"), std::string::npos);
  // So is a corrupt one, naming the item.
  std::string bad = *payload;
  bad[bad.size() / 2] ^= 0x5a;
  auto corrupt = TeamItemCodec::Decode(Item("rover1", TeamItemKind::kSubmap, bad), TestNames());
  ASSERT_FALSE(corrupt.ok());
  EXPECT_NE(corrupt.status().ToString().find("rover1/1/1"), std::string::npos) << corrupt.status().ToString();
}

TEST(TeamItemCodecTest, MatchNamesBothRobotsAndTheirRuns) {
  TeamMatch m;
  m.robot_a = "rover1";
  m.frame_a = 2;
  m.robot_b = "hexa";
  m.incarnation_b = 1;
  m.frame_b = 9;
  m.T_a_b = FourDofTransform(1.0, 2.0, 0.1, 0.5);
  m.covariance = Eigen::Matrix4d::Identity() * 1e-4;
  m.tilt_sigma = 0.01;
  auto in = TeamItemCodec::Decode(Item("rover1", TeamItemKind::kMatch, TeamItemCodec::Match(m)), TestNames());
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  EXPECT_EQ(in->match.letter_a, 'a');
  EXPECT_EQ(in->match.letter_b, 'b');
  EXPECT_EQ(in->match.frame_b, (uint64_t{1} << 40) | 9);
  EXPECT_NEAR(in->match.T_a_b.yaw(), 0.5, 1e-12);
  auto attempt = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kAttempt, TeamItemCodec::Attempt(m, false, "no match")), TestNames());
  ASSERT_TRUE(attempt.ok());
  EXPECT_FALSE(attempt->matched);
  EXPECT_EQ(attempt->outcome, "no match");
}

TEST(TeamItemCodecTest, DetectionNamesTheObservedRobotOrLandmark) {
  TeamDetection d;
  d.time = Timestamp::FromSeconds(41.25);
  d.observed = "rover1";
  d.tag_id = 12;
  d.T_observer_observed.translation() = Eigen::Vector3d(3.5, -0.4, -2.1);
  d.T_observer_observed.linear() = Eigen::AngleAxisd(2.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  d.covariance = Matrix6d::Identity() * 0.003;
  d.covariance(0, 5) = d.covariance(5, 0) = 0.0004;
  d.distance = 4.2;
  d.view_angle = 0.5;
  auto in = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kDetection, TeamItemCodec::Detection(1, d)), TestNames());
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  EXPECT_EQ(in->kind, TeamInput::Kind::kDetection);
  const TeamDetection& got = in->detection;
  EXPECT_EQ(got.observer, "hexa");
  EXPECT_EQ(got.observer_letter, 'b');
  EXPECT_EQ(got.observed, "rover1");
  EXPECT_EQ(got.observed_letter, 'a');
  EXPECT_FALSE(got.landmark);
  EXPECT_EQ(got.tag_id, 12);
  EXPECT_EQ(got.time, d.time);
  EXPECT_TRUE(got.T_observer_observed.isApprox(d.T_observer_observed, 1e-12));
  EXPECT_TRUE(got.covariance.isApprox(d.covariance, 1e-12));
  EXPECT_DOUBLE_EQ(got.distance, 4.2);
  EXPECT_FALSE(got.has_alternative);
  // IPPE's other minimum travels with it.
  TeamDetection two = d;
  two.has_alternative = true;
  two.T_observer_observed_alternative =
      d.T_observer_observed * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitX());
  auto both = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kDetection, TeamItemCodec::Detection(1, two)),
                                    TestNames());
  ASSERT_TRUE(both.ok()) << both.status().ToString();
  EXPECT_TRUE(both->detection.has_alternative);
  EXPECT_TRUE(
      both->detection.T_observer_observed_alternative.isApprox(two.T_observer_observed_alternative, 1e-12));

  d.observed = "lander";
  d.landmark = true;
  auto lander = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kDetection, TeamItemCodec::Detection(1, d)), TestNames());
  ASSERT_TRUE(lander.ok());
  EXPECT_TRUE(lander->detection.landmark);
  EXPECT_EQ(lander->detection.observed_letter, 0);

  // A covariance that is not one, and no name.
  TeamDetection bad = d;
  bad.covariance(2, 2) = -1.0;
  EXPECT_FALSE(TeamItemCodec::Decode(Item("hexa", TeamItemKind::kDetection, TeamItemCodec::Detection(1, bad)), TestNames()).ok());
  bad = d;
  bad.covariance = Matrix6d::Zero();
  EXPECT_FALSE(TeamItemCodec::Decode(Item("hexa", TeamItemKind::kDetection, TeamItemCodec::Detection(1, bad)), TestNames()).ok());
  bad = d;
  bad.observed.clear();
  EXPECT_FALSE(TeamItemCodec::Decode(Item("hexa", TeamItemKind::kDetection, TeamItemCodec::Detection(1, bad)), TestNames()).ok());
}

TEST(TeamItemCodecTest, RefusesWhatATeammateCouldGetWrong) {
  const auto names = TestNames();
  // Not a protobuf, unknown kind.
  EXPECT_FALSE(TeamItemCodec::Decode(Item("hexa", TeamItemKind::kFrameSwitch, "\xff\xff\xff"), names).ok());
  StoreItem unknown = Item("hexa", TeamItemKind::kFrameSwitch, "");
  unknown.kind = 99;
  EXPECT_FALSE(TeamItemCodec::Decode(unknown, names).ok());
  // NaN in a pose, a rotation that is not one, a covariance of the wrong size.
  exchange::FrameSwitchItem m;
  m.ParseFromString(TeamItemCodec::FrameSwitch(0, Switch()));
  exchange::FrameSwitchItem nan = m;
  nan.mutable_t_old_new()->set_tx(std::numeric_limits<double>::quiet_NaN());
  EXPECT_FALSE(TeamItemCodec::Decode(Item("hexa", TeamItemKind::kFrameSwitch, nan.SerializeAsString()), names).ok());
  exchange::FrameSwitchItem skew = m;
  skew.mutable_t_old_new()->set_qw(3.0);
  EXPECT_FALSE(TeamItemCodec::Decode(Item("hexa", TeamItemKind::kFrameSwitch, skew.SerializeAsString()), names).ok());
  exchange::FrameSwitchItem short_cov = m;
  short_cov.mutable_t_old_new()->mutable_covariance()->RemoveLast();
  auto s = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kFrameSwitch, short_cov.SerializeAsString()), names);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.status().ToString().find("20 entries"), std::string::npos) << s.status().ToString();
  exchange::FrameSwitchItem self = m;
  self.set_new_frame(self.old_frame());
  EXPECT_FALSE(TeamItemCodec::Decode(Item("hexa", TeamItemKind::kFrameSwitch, self.SerializeAsString()), names).ok());
}

TEST(TeamItemCodecTest, GnssFixRoundTripsAndLiesAreRefused) {
  TeamGnssFix g;
  g.fix.time = Timestamp::FromSeconds(42.25);
  g.fix.latitude = -0.61;
  g.fix.longitude = 2.63;
  g.fix.height = 350.5;
  g.fix.covariance << 2.0, 0.3, 0.0, 0.3, 1.5, 0.0, 0.0, 0.0, 9.0;
  g.fix.quality = GnssQuality::kRtkFloat;
  g.antenna = Eigen::Vector3d(0.2, 0.0, 1.1);
  auto in =
      TeamItemCodec::Decode(Item("hexa", TeamItemKind::kGnssFix, TeamItemCodec::GnssFix(2, g)), TestNames());
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  EXPECT_EQ(in->kind, TeamInput::Kind::kGnssFix);
  EXPECT_EQ(in->gnss.letter, 'b');
  EXPECT_EQ(in->gnss.run, 2u);
  EXPECT_EQ(in->gnss.fix.time, g.fix.time);
  EXPECT_EQ(in->gnss.fix.latitude, g.fix.latitude);
  EXPECT_EQ(in->gnss.fix.longitude, g.fix.longitude);
  EXPECT_EQ(in->gnss.fix.height, g.fix.height);
  EXPECT_TRUE(in->gnss.fix.covariance.isApprox(g.fix.covariance, 1e-15));
  EXPECT_EQ(in->gnss.fix.quality, GnssQuality::kRtkFloat);
  EXPECT_TRUE(in->gnss.antenna.isApprox(g.antenna, 1e-15));
  auto refused = [&](const TeamGnssFix& bad) {
    auto out = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kGnssFix, TeamItemCodec::GnssFix(2, bad)),
                                     TestNames());
    return out.ok() ? std::string() : out.status().ToString();
  };
  TeamGnssFix bad = g;
  bad.fix.latitude = 2.0;  // beyond the pole
  EXPECT_NE(refused(bad).find("out of range"), std::string::npos);
  bad = g;
  bad.fix.height = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(refused(bad).find("out of range"), std::string::npos);
  bad = g;
  bad.fix.covariance(2, 2) = -1.0;
  EXPECT_NE(refused(bad).find("positive definite"), std::string::npos);
  bad = g;
  bad.fix.quality = GnssQuality::kNone;
  EXPECT_NE(refused(bad).find("not a fix"), std::string::npos);
  bad = g;
  bad.antenna.x() = 1e6;
  EXPECT_NE(refused(bad).find("antenna"), std::string::npos);
  exchange::GnssFixItem short_covariance;
  short_covariance.ParseFromString(TeamItemCodec::GnssFix(2, g));
  short_covariance.mutable_covariance()->RemoveLast();
  auto out = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kGnssFix, short_covariance.SerializeAsString()),
                                   TestNames());
  EXPECT_NE(out.status().ToString().find("9 values"), std::string::npos);
  EXPECT_NE(out.status().ToString().find("gnss_fix"), std::string::npos);  // names the item
}

std::vector<TeamPlaneObservation> PlaneObservations() {
  // Submap 6 of hexa's run 1: a plane it creates, and one that re-observes rover1's landmark.
  TeamPlaneObservation own;
  own.observer = "hexa";
  own.observer_incarnation = 1;
  own.frame = 6;
  own.creator = "hexa";
  own.creator_incarnation = 1;
  own.creator_frame = 6;
  own.plane = 3;
  own.observer_plane = 3;
  own.normal = Eigen::Vector3d(0.6, 0.0, 0.8);
  own.offset = -2.5;
  own.centroid = Eigen::Vector3d(1.0, 2.0, 0.5);
  own.covariance << 4e-4, 1e-5, 2e-5, 1e-5, 3e-4, -1e-5, 2e-5, -1e-5, 1e-3;
  TeamPlaneObservation seen = own;
  seen.creator = "rover1";
  seen.creator_incarnation = 0;
  seen.creator_frame = 11;
  seen.plane = 255;
  seen.observer_plane = 1;
  seen.normal = Eigen::Vector3d(0.0, -1.0, 0.0);
  seen.offset = 7.25;
  seen.centroid = Eigen::Vector3d(-3.0, 0.25, 1.5);
  seen.covariance = Eigen::Vector3d(1e-4, 2e-4, 5e-3).asDiagonal();
  return {own, seen};
}

TEST(TeamItemCodecTest, PlaneObservationsNameTheirRobotsRunsAndFrames) {
  EXPECT_EQ(LaneOf(TeamItemKind::kPlaneObservations), LaneOf(TeamItemKind::kMatch));
  const std::vector<TeamPlaneObservation> sent = PlaneObservations();
  auto in = TeamItemCodec::Decode(
      Item("hexa", TeamItemKind::kPlaneObservations, TeamItemCodec::PlaneObservations(sent)), TestNames());
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  EXPECT_EQ(in->kind, TeamInput::Kind::kPlaneObservations);
  EXPECT_EQ(in->robot, "hexa");
  EXPECT_EQ(in->letter, 'b');
  ASSERT_EQ(in->planes.size(), 2u);
  const char creator_letters[2] = {'b', 'a'};
  const uint64_t creator_frames[2] = {(uint64_t{1} << 40) | 6, 11};
  for (size_t k = 0; k < 2; ++k) {
    SCOPED_TRACE(k);
    const TeamPlaneObservation& got = in->planes[k];
    const TeamPlaneObservation& want = sent[k];
    EXPECT_EQ(got.observer, "hexa");
    EXPECT_EQ(got.observer_letter, 'b');
    EXPECT_EQ(got.observer_incarnation, 1u);
    EXPECT_EQ(got.frame, (uint64_t{1} << 40) | 6);
    EXPECT_EQ(got.creator, want.creator);
    EXPECT_EQ(got.creator_letter, creator_letters[k]);
    EXPECT_EQ(got.creator_incarnation, want.creator_incarnation);
    EXPECT_EQ(got.creator_frame, creator_frames[k]);
    EXPECT_EQ(got.plane, want.plane);
    EXPECT_EQ(got.observer_plane, want.observer_plane);
    EXPECT_EQ(got.normal, want.normal);
    EXPECT_EQ(got.offset, want.offset);
    EXPECT_EQ(got.centroid, want.centroid);
    EXPECT_EQ(got.covariance, want.covariance);
  }
}

TEST(TeamItemCodecTest, PlaneObservationsRefuseWhatATeammateCouldGetWrong) {
  const auto refused = [](const std::vector<TeamPlaneObservation>& bad) {
    auto out = TeamItemCodec::Decode(
        Item("hexa", TeamItemKind::kPlaneObservations, TeamItemCodec::PlaneObservations(bad)), TestNames());
    return out.ok() ? std::string() : out.status().ToString();
  };
  const std::vector<TeamPlaneObservation> good = PlaneObservations();
  ASSERT_EQ(refused(good), "");
  const auto with = [&](const std::function<void(TeamPlaneObservation*)>& spoil) {
    std::vector<TeamPlaneObservation> bad = good;
    spoil(&bad[1]);
    return refused(bad);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  EXPECT_NE(refused({}).find("no observations"), std::string::npos) << refused({});
  EXPECT_NE(refused({}).find("plane_observations"), std::string::npos);  // names the item
  const std::vector<TeamPlaneObservation> many(TeamItemCodec::kMaxPlaneObservations + 1, good[0]);
  EXPECT_NE(refused(many).find("4097 observations"), std::string::npos) << refused(many);
  std::vector<TeamPlaneObservation> most(TeamItemCodec::kMaxPlaneObservations, good[0]);
  EXPECT_EQ(refused(most), "");

  const std::function<void(TeamPlaneObservation*)> not_finite[] = {
      [&](TeamPlaneObservation* o) { o->normal.x() = nan; },
      [&](TeamPlaneObservation* o) { o->offset = inf; },
      [&](TeamPlaneObservation* o) { o->centroid.z() = -inf; },
      [&](TeamPlaneObservation* o) { o->covariance(1, 2) = nan; },
  };
  std::string why;
  for (const auto& spoil : not_finite) {
    why = with(spoil);
    EXPECT_NE(why.find("observation 1: a value is not finite"), std::string::npos) << why;
  }

  why = with([](TeamPlaneObservation* o) { o->normal *= 1.002; });
  EXPECT_NE(why.find("not of unit length"), std::string::npos) << why;
  EXPECT_EQ(with([](TeamPlaneObservation* o) { o->normal *= 1.0005; }), "");
  why = with([](TeamPlaneObservation* o) { o->normal.setZero(); });
  EXPECT_NE(why.find("not of unit length"), std::string::npos) << why;

  why = with([](TeamPlaneObservation* o) { o->covariance(0, 2) += 1e-6; });
  EXPECT_NE(why.find("not symmetric"), std::string::npos) << why;
  why = with([](TeamPlaneObservation* o) { o->covariance(2, 2) = -1e-3; });
  EXPECT_NE(why.find("not positive definite"), std::string::npos) << why;
  EXPECT_NE(with([](TeamPlaneObservation* o) { o->covariance.setZero(); }).find("not positive definite"),
            std::string::npos);

  why = with([](TeamPlaneObservation* o) { o->plane = 256; });
  EXPECT_NE(why.find("plane index 256"), std::string::npos) << why;
  why = with([](TeamPlaneObservation* o) { o->observer_plane = 300; });
  EXPECT_NE(why.find("plane index 300"), std::string::npos) << why;
  why = with([](TeamPlaneObservation* o) { o->observer.clear(); });
  EXPECT_NE(why.find("names no observer"), std::string::npos) << why;
  why = with([](TeamPlaneObservation* o) { o->creator.clear(); });
  EXPECT_NE(why.find("no creator"), std::string::npos) << why;

  // A covariance of the wrong size only comes off the wire.
  for (int entries : {0, 8, 10}) {
    exchange::PlaneObservationsItem m;
    m.ParseFromString(TeamItemCodec::PlaneObservations(good));
    auto* covariance = m.mutable_observations(1)->mutable_covariance();
    while (covariance->size() > entries) covariance->RemoveLast();
    while (covariance->size() < entries) covariance->Add(0.0);
    auto out = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kPlaneObservations, m.SerializeAsString()),
                                     TestNames());
    ASSERT_FALSE(out.ok());
    why = out.status().ToString();
    EXPECT_NE(why.find("has " + std::to_string(entries) + " entries, not 9"), std::string::npos) << why;
  }
}

std::vector<TeamLineObservation> LineObservations() {
  // Submap 6 of hexa's run 1: an edge it creates a landmark with, and one that re-observes rover1's.
  TeamLineObservation own;
  own.observer = "hexa";
  own.observer_incarnation = 1;
  own.frame = 6;
  own.creator = "hexa";
  own.creator_incarnation = 1;
  own.creator_frame = 6;
  own.line = 17;
  own.observer_line = 17;
  own.point = Eigen::Vector3d(3.0, -1.0, 0.4);
  own.direction = Eigen::Vector3d(0.0, 0.6, 0.8);
  own.covariance = Eigen::Vector4d(1e-4, 2e-4, 4e-4, 9e-4).asDiagonal();
  own.covariance(0, 2) = own.covariance(2, 0) = 5e-5;
  TeamLineObservation seen = own;
  seen.creator = "rover1";
  seen.creator_incarnation = 0;
  seen.creator_frame = 11;
  seen.line = 1023;
  seen.observer_line = 2;
  seen.direction = Eigen::Vector3d(1.0, 0.0, 0.0);
  return {own, seen};
}

TEST(TeamItemCodecTest, LineObservationsNameTheirRobotsRunsAndFrames) {
  EXPECT_EQ(LaneOf(TeamItemKind::kLineObservations), LaneOf(TeamItemKind::kMatch));
  const std::vector<TeamLineObservation> sent = LineObservations();
  auto in = TeamItemCodec::Decode(
      Item("hexa", TeamItemKind::kLineObservations, TeamItemCodec::LineObservations(sent)), TestNames());
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  EXPECT_EQ(in->kind, TeamInput::Kind::kLineObservations);
  ASSERT_EQ(in->lines.size(), 2u);
  const char creator_letters[2] = {'b', 'a'};
  const uint64_t creator_frames[2] = {(uint64_t{1} << 40) | 6, 11};
  for (size_t k = 0; k < 2; ++k) {
    SCOPED_TRACE(k);
    const TeamLineObservation& got = in->lines[k];
    const TeamLineObservation& want = sent[k];
    EXPECT_EQ(got.observer_letter, 'b');
    EXPECT_EQ(got.frame, (uint64_t{1} << 40) | 6);
    EXPECT_EQ(got.creator, want.creator);
    EXPECT_EQ(got.creator_letter, creator_letters[k]);
    EXPECT_EQ(got.creator_frame, creator_frames[k]);
    EXPECT_EQ(got.line, want.line);
    EXPECT_EQ(got.observer_line, want.observer_line);
    EXPECT_EQ(got.point, want.point);
    EXPECT_EQ(got.direction, want.direction);
    EXPECT_EQ(got.covariance, want.covariance);
  }
}

TEST(TeamItemCodecTest, LineObservationsRefuseWhatATeammateCouldGetWrong) {
  const auto refused = [](const std::vector<TeamLineObservation>& bad) {
    auto out = TeamItemCodec::Decode(
        Item("hexa", TeamItemKind::kLineObservations, TeamItemCodec::LineObservations(bad)), TestNames());
    return out.ok() ? std::string() : out.status().ToString();
  };
  const std::vector<TeamLineObservation> good = LineObservations();
  ASSERT_EQ(refused(good), "");
  const auto with = [&](const std::function<void(TeamLineObservation*)>& spoil) {
    std::vector<TeamLineObservation> bad = good;
    spoil(&bad[1]);
    return refused(bad);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(refused({}).find("line_observations"), std::string::npos) << refused({});
  const std::vector<TeamLineObservation> many(TeamItemCodec::kMaxLineObservations + 1, good[0]);
  EXPECT_NE(refused(many).find("4097 observations"), std::string::npos) << refused(many);
  std::string why = with([&](TeamLineObservation* o) { o->point.y() = nan; });
  EXPECT_NE(why.find("observation 1: a value is not finite"), std::string::npos) << why;
  why = with([&](TeamLineObservation* o) { o->covariance(3, 1) = nan; });
  EXPECT_NE(why.find("a value is not finite"), std::string::npos) << why;
  why = with([](TeamLineObservation* o) { o->direction *= 1.002; });
  EXPECT_NE(why.find("direction is not of unit length"), std::string::npos) << why;
  why = with([](TeamLineObservation* o) { o->covariance(0, 3) += 1e-6; });
  EXPECT_NE(why.find("not symmetric"), std::string::npos) << why;
  why = with([](TeamLineObservation* o) { o->covariance(3, 3) = -1e-3; });
  EXPECT_NE(why.find("not positive definite"), std::string::npos) << why;
  why = with([](TeamLineObservation* o) { o->line = 1024; });
  EXPECT_NE(why.find("line index 1024"), std::string::npos) << why;
  why = with([](TeamLineObservation* o) { o->creator.clear(); });
  EXPECT_NE(why.find("no creator"), std::string::npos) << why;
  exchange::LineObservationsItem m;
  m.ParseFromString(TeamItemCodec::LineObservations(good));
  m.mutable_observations(0)->mutable_covariance()->RemoveLast();
  auto out = TeamItemCodec::Decode(Item("hexa", TeamItemKind::kLineObservations, m.SerializeAsString()),
                                   TestNames());
  ASSERT_FALSE(out.ok());
  EXPECT_NE(out.status().ToString().find("has 15 entries, not 16"), std::string::npos)
      << out.status().ToString();
}

}  // namespace
}  // namespace cairn
