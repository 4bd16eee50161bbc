// The packed layout: round trips, byte-range cut-outs played by ffmpeg, a killed writer, resume,
// hostile indexes and the file count bound (docs/formats.md, Packed layout).
#include "store/pack.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <malloc.h>

#include <cstdio>
#include <fstream>

#include "core/error.hpp"
#include "core/frame_stamp.hpp"
#include "store/database.hpp"
#include "store/pack_convert.hpp"
#include "store/synthetic.hpp"
#include "store/test_support.hpp"

using namespace panoptes;
using namespace panoptes::store;
using panoptes::store::testing::sample_manifest;
using panoptes::store::testing::TempDir;
namespace fs = std::filesystem;

namespace {

Manifest packed_manifest(int cameras, int tasks, int width = 64, int height = 48) {
  Manifest m = sample_manifest(cameras, tasks, width, height);
  m.video.gop = 1;
  return m;
}

WriterOptions packed_options() {
  WriterOptions o;
  o.layout = LayoutChoice::packed;
  return o;
}

void append_snapshot(DatabaseWriter& w, const Manifest& m, int frame) {
  for (int c = 0; c < m.camera_count(); ++c)
    for (int t = 0; t < m.task_count(); ++t) w.append(c, t, synthetic_frame(c, t, frame, m.image.width, m.image.height));
}

void expect_stamps(const Database& db, int camera, int task, int frames) {
  auto reader = db.stream(camera, task);
  ASSERT_GE(reader->frame_count(), frames);
  for (int f = frames - 1; f >= 0; --f) {
    const auto stamp = read_frame_stamp(reader->read_rgba(f));
    ASSERT_TRUE(stamp.has_value()) << "camera " << camera << " task " << task << " frame " << f;
    EXPECT_EQ(*stamp, (FrameStamp{std::uint32_t(camera), std::uint32_t(task), std::uint32_t(f)}));
  }
}

std::vector<char> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& p, const std::vector<char>& b) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(b.data(), std::streamsize(b.size()));
}

// Sets the manifest's frames_written (a checkpoint the test wants on disk after the writer's end).
void set_frames_written(const fs::path& dir, int frames) {
  const fs::path p = dir / "panoptes.json";
  std::vector<char> b = read_bytes(p);
  std::string text(b.begin(), b.end());
  const auto at = text.find("\"frames_written\":");
  ASSERT_NE(at, std::string::npos);
  const auto end = text.find_first_of(",\n}", at + 17);
  text.replace(at, end - at, "\"frames_written\":" + std::to_string(frames));
  write_bytes(p, std::vector<char>(text.begin(), text.end()));
}

std::size_t count_files(const fs::path& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) ++n;
  return n;
}

std::string run(const std::string& command) {
  std::string out;
  FILE* p = ::popen(command.c_str(), "r");
  if (!p) return out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  ::pclose(p);
  return out;
}

}  // namespace

TEST(Pack, WriteThenReadEveryStreamWithItsChecks) {
  TempDir dir;
  const Manifest m = packed_manifest(3, 2, 63, 37);  // odd size: padded and cropped as files are
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, m, packed_options());
    for (int f = 0; f < 4; ++f) {
      append_snapshot(w, m, f);
      w.checkpoint();
    }
    w.finalize();
  }
  const Database db = Database::open(dir.path);
  ASSERT_TRUE(db.packed());
  EXPECT_EQ(db.frame_count(), 4);
  EXPECT_EQ(db.manifest().image.padded_width, 64);
  for (int c = 0; c < 3; ++c)
    for (int t = 0; t < 2; ++t) expect_stamps(db, c, t, 4);
  const StreamReport quick = db.validate_streams(1, false);
  EXPECT_TRUE(quick.problems.empty()) << quick.problems.front().message;
  const StreamReport deep = db.validate_streams(1, true);
  EXPECT_TRUE(deep.problems.empty()) << deep.problems.front().message;
  EXPECT_GT(deep.bytes, 0);
  const PackedStream ps = db.packed_stream(2, 1);
  ASSERT_EQ(ps.pieces.size(), 5u);  // init + one fragment per checkpoint
  for (int k = 1; k < 5; ++k) EXPECT_EQ(ps.pieces[std::size_t(k)].first_frame, k - 1);
  EXPECT_TRUE(db.damaged_frames(2, 1).empty());
  // No movie file: manifest, camera table, one pack and its index.
  EXPECT_EQ(count_files(dir.path), 4u);
  EXPECT_FALSE(fs::exists(dir.path / "movies"));
}

TEST(Pack, AStreamCutOutByByteRangesPlaysInFfmpeg) {
  TempDir dir;
  const Manifest m = packed_manifest(2, 2);
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, m, packed_options());
    for (int f = 0; f < 3; ++f) {
      append_snapshot(w, m, f);
      w.checkpoint();
    }
    w.finalize();
  }
  const Database db = Database::open(dir.path);
  const PackedStream ps = db.packed_stream(1, 1);
  // Cut out with nothing but the byte ranges (as `dd` or an HTTP Range request would).
  std::vector<char> movie;
  for (const auto& p : ps.pieces) {
    const std::vector<char> all = read_bytes(p.file);
    movie.insert(movie.end(), all.begin() + std::ptrdiff_t(p.offset), all.begin() + std::ptrdiff_t(p.offset + p.size));
  }
  const fs::path cut = dir.path / "cut.mp4";
  write_bytes(cut, movie);
  const std::string frames = run("ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                                 "stream=nb_read_frames,width,height -of csv=p=0 '" + cut.string() + "' 2>&1");
  EXPECT_EQ(frames, "64,48,3\n");
  const std::string decode = run("ffmpeg -v error -i '" + cut.string() + "' -f null - 2>&1; echo rc=$?");
  EXPECT_EQ(decode, "rc=0\n");
  // MovieReader reads the cut-out file as any movie, with its frame checks.
  video::MovieReader reader(cut.string(), db.frame_checks(1, 1));
  ASSERT_EQ(reader.frame_count(), 3);
  EXPECT_TRUE(reader.check_frames().empty());
  const auto stamp = read_frame_stamp(reader.read_rgba(2));
  ASSERT_TRUE(stamp.has_value());
  EXPECT_EQ(*stamp, (FrameStamp{1, 1, 2}));
}

TEST(Pack, KilledWriterKeepsEveryCheckpointedSnapshot) {
  TempDir dir;
  const Manifest m = packed_manifest(3, 2);
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(ready[0]);
    try {
      DatabaseWriter w = DatabaseWriter::create(dir.path, m, packed_options());
      for (int f = 0; f < 3; ++f) {
        append_snapshot(w, m, f);
        w.checkpoint();
      }
      // A fourth snapshot flushed (in the pack and index) but never checkpointed, a fifth half done.
      append_snapshot(w, m, 3);
      w.flush();
      w.append(0, 0, synthetic_frame(0, 0, 4, 64, 48));
      const char ok = 'k';
      if (::write(ready[1], &ok, 1) != 1) ::_exit(3);
      while (true) ::pause();
    } catch (...) {
      ::_exit(2);
    }
  }
  ::close(ready[1]);
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1) << "writer child failed";
  ::close(ready[0]);
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  const Database db = Database::open(dir.path);
  EXPECT_EQ(db.status(), Status::interrupted);
  EXPECT_EQ(db.frame_count(), 3);
  for (int cam = 0; cam < 3; ++cam)
    for (int t = 0; t < 2; ++t) expect_stamps(db, cam, t, 3);
  EXPECT_TRUE(db.validate_streams(1, true).problems.empty());
}

TEST(Pack, KilledAtEveryMomentOfARoundStillPlaysTheCheckpoint) {
  // The order the writer keeps (pack bytes, then index round, then manifest) simulated at each cut:
  // an index round cut anywhere, and index records naming bytes the pack lost, are ignored.
  TempDir dir;
  const Manifest m = packed_manifest(2, 2);
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, m, packed_options());
    for (int f = 0; f < 2; ++f) {
      append_snapshot(w, m, f);
      w.checkpoint();
    }
    append_snapshot(w, m, 2);
    w.flush();  // round 3 indexed
  }
  set_frames_written(dir.path, 2);  // the checkpoint before it
  const fs::path idx = dir.path / "packs" / pack_index_name(0, 0), pack = dir.path / "packs" / pack_file_name(0, 0);
  const std::vector<char> full_idx = read_bytes(idx), full_pack = read_bytes(pack);
  const std::size_t round = 4 * kPackRecordBytes;
  for (std::size_t cut = full_idx.size() - round; cut <= full_idx.size(); cut += 7) {
    write_bytes(idx, std::vector<char>(full_idx.begin(), full_idx.begin() + std::ptrdiff_t(cut)));
    const Database db = Database::open(dir.path);
    for (int c = 0; c < 2; ++c)
      for (int t = 0; t < 2; ++t) expect_stamps(db, c, t, 2);
  }
  // The pack lost the last snapshot's bytes but the index names them: the streams end before them.
  write_bytes(idx, full_idx);
  const PackedStream before = Database::open(dir.path).packed_stream(0, 0);
  write_bytes(pack, std::vector<char>(full_pack.begin(), full_pack.begin() + std::ptrdiff_t(before.pieces[3].offset)));
  const Database db = Database::open(dir.path);
  for (int c = 0; c < 2; ++c)
    for (int t = 0; t < 2; ++t) expect_stamps(db, c, t, 2);
}

TEST(Pack, ResumeContinuesInANewSegment) {
  TempDir dir;
  const Manifest m = packed_manifest(2, 3);
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, m, packed_options());
    for (int f = 0; f < 3; ++f) {
      append_snapshot(w, m, f);
      w.checkpoint();
    }
    append_snapshot(w, m, 3);  // flushed at the interrupted end, beyond the checkpoint of 3
    w.flush();
  }  // destroyed without finalize: interrupted with 4 complete snapshots
  Database before = Database::open(dir.path);
  ASSERT_EQ(before.frame_count(), 4);
  {
    // Continue from the checkpoint of 3 frames as a restarted simulation would (rewrite manifest).
    DatabaseWriter w = DatabaseWriter::resume(dir.path, m, packed_options());
    EXPECT_EQ(w.manifest().frames_written, 4);
    for (int f = 4; f < 6; ++f) {
      append_snapshot(w, m, f);
      w.checkpoint();
    }
    w.finalize();
  }
  const Database db = Database::open(dir.path);
  ASSERT_EQ(db.manifest().packs.size(), 2u);
  EXPECT_EQ(db.manifest().packs[1].first_frame, 4);
  EXPECT_EQ(db.frame_count(), 6);
  for (int c = 0; c < 2; ++c)
    for (int t = 0; t < 3; ++t) expect_stamps(db, c, t, 6);
  EXPECT_TRUE(db.validate_streams(1, true).problems.empty());
}

TEST(Pack, ResumeCutsAFragmentThatHoldsTheSeam) {
  TempDir dir;
  const Manifest m = packed_manifest(1, 2);
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, m, packed_options());
    for (int f = 0; f < 2; ++f) {
      append_snapshot(w, m, f);
      w.checkpoint();
    }
    append_snapshot(w, m, 2);
    append_snapshot(w, m, 3);
    w.flush();  // one fragment of frames 2 and 3
  }
  set_frames_written(dir.path, 3);  // a checkpoint of 3: the seam is inside that fragment
  {
    WriterOptions o = packed_options();
    DatabaseWriter w = DatabaseWriter::resume(dir.path, m, o, -1);
    EXPECT_EQ(w.manifest().frames_written, 3);
    append_snapshot(w, m, 3);
    w.finalize();
  }
  const Database db = Database::open(dir.path);
  EXPECT_EQ(db.frame_count(), 4);
  for (int t = 0; t < 2; ++t) expect_stamps(db, 0, t, 4);
}

TEST(Pack, HostileIndexesGiveClearErrors) {
  TempDir dir;
  const Manifest m = packed_manifest(2, 2);
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, m, packed_options());
    for (int f = 0; f < 2; ++f) {
      append_snapshot(w, m, f);
      w.checkpoint();
    }
    w.finalize();
  }
  const fs::path idx = dir.path / "packs" / pack_index_name(0, 0);
  const std::vector<char> good = read_bytes(idx);
  auto reopen_error = [&](const std::vector<char>& bytes) {
    write_bytes(idx, bytes);
    const Database db = Database::open(dir.path);
    try {
      db.stream(1, 1)->read_rgba(1);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  auto with = [&](std::size_t at, std::uint64_t value, int n) {
    std::vector<char> b = good;
    for (int i = 0; i < n; ++i) b[at + std::size_t(i)] = char(value >> (8 * i));
    return b;
  };
  // Truncated into its header.
  EXPECT_NE(reopen_error(std::vector<char>(good.begin(), good.begin() + 40)).find("truncated"), std::string::npos);
  EXPECT_NE(reopen_error(with(0, 0x58, 1)).find("not a pack index"), std::string::npos);
  EXPECT_NE(reopen_error(with(24, 7, 4)).find("lists 7 cameras"), std::string::npos);
  EXPECT_NE(reopen_error(with(12, 80, 4)).find("header size"), std::string::npos);
  EXPECT_NE(reopen_error(with(64, 1, 4)).find("damaged"), std::string::npos);  // camera list vs CRC
  // Records: the stream (1, 1) is record 3 of each round. Out-of-range offset with a valid check word.
  const std::size_t header = good.size() - 2 * 4 * kPackRecordBytes;
  auto record = [&](std::size_t round, PackRecord r) {
    std::vector<char> b = good;
    const std::size_t at = header + (round * 4 + 3) * kPackRecordBytes;
    const std::uint32_t check = pack_record_check(r, 3);
    for (int i = 0; i < 8; ++i) b[at + std::size_t(i)] = char(r.offset >> (8 * i));
    for (int i = 0; i < 4; ++i) {
      b[at + 8 + std::size_t(i)] = char(r.size >> (8 * i));
      b[at + 12 + std::size_t(i)] = char(r.first_frame >> (8 * i));
      b[at + 16 + std::size_t(i)] = char(r.frames >> (8 * i));
      b[at + 20 + std::size_t(i)] = char(check >> (8 * i));
    }
    return b;
  };
  // Past the pack's end: the record is the lost tail, the stream is truncated (clear, no crash).
  EXPECT_NE(reopen_error(record(1, {std::uint64_t(1) << 40, 100, 1, 1})).find("truncated"), std::string::npos);
  // Over the init segment, and overlapping the previous fragment.
  EXPECT_NE(reopen_error(record(1, {8, 100, 1, 1})).find("overlap the init segment"), std::string::npos);
  write_bytes(idx, good);
  const PackedStream ps = Database::open(dir.path).packed_stream(1, 1);
  EXPECT_NE(reopen_error(record(1, {ps.pieces[1].offset + 4, std::uint32_t(ps.pieces[2].size), 1, 1})).find("overlap"),
            std::string::npos);
  // A flipped bit in a record.
  std::vector<char> flipped = good;
  flipped[header + 3 * kPackRecordBytes + 9] ^= 1;
  EXPECT_NE(reopen_error(flipped).find("damaged"), std::string::npos);
  // Huge frame counts.
  EXPECT_NE(reopen_error(record(1, {ps.pieces[2].offset, std::uint32_t(ps.pieces[2].size), 1, 0xfffffff0u})).find("claims"),
            std::string::npos);
  // Deep check reports without throwing.
  write_bytes(idx, flipped);
  const StreamReport r = Database::open(dir.path).validate_streams(1, false);
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_EQ(r.problems[0].kind, StreamProblem::Kind::unreadable);
}

TEST(Pack, ManyStreamsLiveInAFewFiles) {
  TempDir dir;
  Manifest m = packed_manifest(100, 12, 40, 32);  // 1,200 streams: packed by default (auto)
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, m);
    ASSERT_EQ(w.manifest().layout, Layout::packed);
    for (int f = 0; f < 2; ++f) {
      append_snapshot(w, m, f);
      w.checkpoint();
    }
    w.finalize();
  }
  EXPECT_EQ(count_files(dir.path), 4u);
  const Database db = Database::open(dir.path);
  EXPECT_TRUE(db.validate_streams(2, false).problems.empty());
  expect_stamps(db, 99, 11, 2);
  // Four ranks (cameras round-robin), as in situ: one pack and index per rank.
  TempDir dir2;
  {
    std::vector<DatabaseWriter> writers;
    for (int r = 0; r < 4; ++r) {
      WriterOptions o;
      o.rank = r;
      o.ranks = 4;
      o.writes_manifest = r == 0;
      for (int c = r; c < 100; c += 4) o.owned_cameras.push_back(c);
      writers.push_back(DatabaseWriter::create(dir2.path, m, o));
    }
    for (int r = 0; r < 4; ++r)
      for (int c = r; c < 100; c += 4)
        for (int t = 0; t < 12; ++t) writers[std::size_t(r)].append(c, t, synthetic_frame(c, t, 0, 40, 32));
    for (int r = 3; r >= 0; --r) writers[std::size_t(r)].flush();
    writers[0].finalize(1);
    for (int r = 1; r < 4; ++r) writers[std::size_t(r)].finalize();
  }
  EXPECT_EQ(count_files(dir2.path), 2u + 8u);
  const Database db2 = Database::open(dir2.path);
  EXPECT_TRUE(db2.validate_streams(2, false).problems.empty());
  expect_stamps(db2, 97, 5, 1);
}

// Memory of an idle stream between snapshots (the crux at 10^6 streams): heap in use (mallinfo2)
// after the first checkpoint minus right after create() (the manifest, camera table and the shared
// encoder are there before), per stream; at the second checkpoint it must not have grown. Printed;
// bounded at 512 bytes (the files layout keeps an FFmpeg muxer, ~1 MB, per stream).
TEST(Pack, IdleStreamsHoldAFewHundredBytes) {
  TempDir dir;
  const int cameras = 1024, tasks = 4;
  Manifest m = packed_manifest(cameras, tasks, 40, 32);
  const Image frame = synthetic_frame(0, 0, 0, 40, 32);
  DatabaseWriter w = DatabaseWriter::create(dir.path, m, packed_options());
  w.append(0, 0, frame);  // the encoder pool's first encoders and x264's one-time tables
  const std::size_t before = mallinfo2().uordblks;
  for (int c = 0; c < cameras; ++c)
    for (int t = c == 0 ? 1 : 0; t < tasks; ++t) w.append(c, t, frame);
  w.checkpoint();
  const std::size_t first = mallinfo2().uordblks;
  for (int c = 0; c < cameras; ++c)
    for (int t = 0; t < tasks; ++t) w.append(c, t, frame);
  w.checkpoint();
  const std::size_t second = mallinfo2().uordblks;
  const double per_stream = (double(first) - double(before)) / (cameras * tasks);
  const double growth = (double(second) - double(first)) / (cameras * tasks);
  std::printf("packed writer: %.0f bytes of heap per idle stream after a snapshot, %+.0f after the next\n", per_stream,
              growth);
  EXPECT_LT(per_stream, 512);
  EXPECT_LT(growth, 64);
  w.finalize();
}

// `panoptes pack` / `unpack`: every packet bitwise the source's, both ways, with P-frames too.
TEST(Pack, PackAndUnpackKeepEveryPacketBitwise) {
  for (const int gop : {1, 3}) {
    TempDir files, packed, unpacked;
    Manifest m = sample_manifest(3, 2, 48, 40);
    m.video.gop = gop;
    {
      WriterOptions o;
      o.layout = LayoutChoice::files;
      DatabaseWriter w = DatabaseWriter::create(files.path, m, o);
      for (int f = 0; f < 4; ++f) {
        append_snapshot(w, m, f);
        w.checkpoint();
      }
      w.finalize();
    }
    fs::remove_all(packed.path);
    pack_database(files.path, packed.path);
    fs::remove_all(unpacked.path);
    unpack_database(packed.path, unpacked.path);
    const Database a = Database::open(files.path), b = Database::open(packed.path), c = Database::open(unpacked.path);
    ASSERT_TRUE(b.packed());
    ASSERT_FALSE(c.packed());
    EXPECT_EQ(b.frame_count(), 4);
    EXPECT_EQ(count_files(packed.path), 4u);
    EXPECT_EQ(count_files(unpacked.path), 2u + 6u);
    std::vector<std::uint8_t> pa, pb, pc;
    for (int cam = 0; cam < 3; ++cam)
      for (int t = 0; t < 2; ++t) {
        auto ra = a.stream(cam, t), rb = b.stream(cam, t), rc = c.stream(cam, t);
        ASSERT_EQ(rb->frame_count(), 4);
        ASSERT_EQ(rc->frame_count(), 4);
        for (int f = 0; f < 4; ++f) {
          ra->read_packet(f, pa);
          rb->read_packet(f, pb);
          rc->read_packet(f, pc);
          EXPECT_EQ(pa, pb) << "gop " << gop << " camera " << cam << " task " << t << " frame " << f;
          EXPECT_EQ(pa, pc) << "gop " << gop << " camera " << cam << " task " << t << " frame " << f;
          EXPECT_EQ(rb->is_keyframe(f), ra->is_keyframe(f));
        }
        expect_stamps(b, cam, t, 4);
      }
    EXPECT_TRUE(b.validate_streams(1, true).problems.empty());
    EXPECT_TRUE(c.validate_streams(1, true).problems.empty());
    // Refusals: into a database, or packing a packed one.
    EXPECT_THROW(pack_database(files.path, unpacked.path), FileError);
    TempDir again;
    fs::remove_all(again.path);
    EXPECT_THROW(pack_database(packed.path, again.path), Error);
  }
}

// The manifest's layout fields: round trip, and clear refusals of what this build cannot read.
TEST(Pack, ManifestLayoutFieldsAreCheckedOnRead) {
  Manifest m = packed_manifest(2, 1);
  m.layout = Layout::packed;
  m.packs = {{0, 0, 4}, {1, 7, 2}};
  const nlohmann::json j = to_json(m);
  const Manifest back = manifest_from_json(j, "test", {});
  EXPECT_EQ(back.layout, Layout::packed);
  EXPECT_EQ(back.packs, m.packs);
  auto error_of = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json k = j;
    edit(k);
    try {
      manifest_from_json(k, "test", {});
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of([](nlohmann::json& k) { k["layout"] = "zip"; }).find("\"zip\" is not a layout"), std::string::npos);
  EXPECT_NE(error_of([](nlohmann::json& k) { k.erase("packs"); }).find("must list its segments"), std::string::npos);
  EXPECT_NE(error_of([](nlohmann::json& k) { k["packs"][1]["segment"] = 0; }).find("ascending"), std::string::npos);
  EXPECT_NE(error_of([](nlohmann::json& k) { k["packs"][1]["first_frame"] = -1; }).find("non-decreasing"), std::string::npos);
  EXPECT_NE(error_of([](nlohmann::json& k) { k["packs"][0]["ranks"] = 0; }).find("1..1000000"), std::string::npos);
  // A files database writes no layout field (older readers see what they always saw).
  EXPECT_FALSE(to_json(packed_manifest(2, 1)).contains("layout"));
}

// Overwriting a packed database removes exactly its packs (every segment), not a user's file beside.
TEST(Pack, OverwriteRemovesEverySegmentsPacks) {
  TempDir dir;
  const Manifest m = packed_manifest(2, 1);
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, m, packed_options());
    append_snapshot(w, m, 0);
    w.checkpoint();
  }
  {
    DatabaseWriter w = DatabaseWriter::resume(dir.path, m, packed_options());
    append_snapshot(w, m, 1);
    w.finalize();
  }
  ASSERT_TRUE(fs::exists(dir.path / "packs" / pack_file_name(1, 0)));
  write_bytes(dir.path / "packs" / "notes.txt", {'k'});
  WriterOptions o;
  o.overwrite = true;
  o.layout = LayoutChoice::files;
  {
    DatabaseWriter w = DatabaseWriter::create(dir.path, m, o);
    append_snapshot(w, m, 0);
    w.finalize();
  }
  for (int s = 0; s < 2; ++s) {
    EXPECT_FALSE(fs::exists(dir.path / "packs" / pack_file_name(s, 0)));
    EXPECT_FALSE(fs::exists(dir.path / "packs" / pack_index_name(s, 0)));
  }
  EXPECT_TRUE(fs::exists(dir.path / "packs" / "notes.txt"));
  const Database db = Database::open(dir.path);
  EXPECT_FALSE(db.packed());
  expect_stamps(db, 1, 0, 1);
}
