// key_pixels_probe: types keys into a window with XTest and measures, from outside the program, how
// long it takes until the window's pixels change (issue 30.3 / 32.5). Used by desktop_latency_bench
// (scripts/bench), which starts Xvfb and `panoptes play` and compares these figures with the ones the
// player's HUD measured itself (`play --latency-log`).
//
//   key_pixels_probe --window Panoptes --keys Up,Down --count 60 --out probe.tsv
//
// For every key: grab a reference of the sampled rows, send press + release (XTestFakeKeyEvent, then
// XFlush), note the monotonic time, and poll the same rows (XGetImage) until enough pixels differ. The
// change is dated at the middle of the poll that first saw it (the poll period is printed: it bounds
// the error). Keys are spaced by a random gap so they land at every phase of the player's frame loop.
// Output: one TSV line per key: index, key, send time (CLOCK_MONOTONIC ms, read just before sending),
// change time, latency ms, fraction of sampled pixels changed (0 = no change seen before the timeout),
// how long sending took (ms; long = the probe was descheduled), and the poll gap in which the change
// was seen (ms; the change time is uncertain by half of it).
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/extensions/XTest.h>
#include <X11/keysym.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace {

double mono_ms() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) / 1e6;
}

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "key_pixels_probe: %s\n", what.c_str());
  std::exit(2);
}

// The first window (depth first) whose WM_NAME starts with `prefix` and that is mapped.
Window find_window(Display* dpy, Window w, const std::string& prefix) {
  char* name = nullptr;
  if (XFetchName(dpy, w, &name) && name) {
    const bool match = std::string(name).rfind(prefix, 0) == 0;
    XFree(name);
    XWindowAttributes a{};
    if (match && XGetWindowAttributes(dpy, w, &a) && a.map_state == IsViewable) return w;
  }
  Window root = 0, parent = 0, *children = nullptr;
  unsigned n = 0;
  if (!XQueryTree(dpy, w, &root, &parent, &children, &n)) return 0;
  Window found = 0;
  for (unsigned i = 0; i < n && !found; ++i) found = find_window(dpy, children[i], prefix);
  if (children) XFree(children);
  return found;
}

struct Sampler {
  Display* dpy;
  Window win;
  int x0, x1;
  std::vector<int> rows;
  // Grabs the sampled rows as packed 32-bit pixels.
  std::vector<std::uint32_t> grab() const {
    std::vector<std::uint32_t> px;
    px.reserve(rows.size() * std::size_t(x1 - x0));
    for (int y : rows) {
      XImage* img = XGetImage(dpy, win, x0, y, unsigned(x1 - x0), 1, AllPlanes, ZPixmap);
      if (!img) fail("XGetImage failed (window gone?)");
      for (int x = 0; x < x1 - x0; ++x) px.push_back(std::uint32_t(XGetPixel(img, x, 0)));
      XDestroyImage(img);
    }
    return px;
  }
};

// Fraction of pixels whose channels differ by more than `tol` levels.
double changed_fraction(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b, int tol) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    for (int s = 0; s < 24; s += 8) {
      const int d = int((a[i] >> s) & 255) - int((b[i] >> s) & 255);
      if (d > tol || d < -tol) {
        ++n;
        break;
      }
    }
  }
  return a.empty() ? 0 : double(n) / double(a.size());
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::size_t p = 0;
  for (;;) {
    const std::size_t q = s.find(sep, p);
    out.push_back(s.substr(p, q - p));
    if (q == std::string::npos) break;
    p = q + 1;
  }
  return out;
}

void usage() {
  std::puts(
      "Usage: key_pixels_probe [--window PREFIX] [--keys K1,K2,...] [--count N] [--gap-ms MIN,MAX]\n"
      "                        [--threshold FRACTION] [--timeout-ms MS] [--final-key KEY] [--out FILE]\n"
      "Types the keys (X keysym names, cycled) into the first window whose title starts with PREFIX\n"
      "(default Panoptes) with XTest, and measures key -> changed pixels from outside the program.\n"
      "Samples 24 rows of the left 60 % of the window (clear of the HUD panels); a key counts as shown\n"
      "when more than FRACTION (default 0.02) of the sampled pixels changed by more than 24 levels.\n"
      "Writes one TSV line per key: index key send_ms change_ms latency_ms changed_fraction send_duration_ms\n"
      "poll_gap_ms.\n"
      "--final-key KEY is typed at the end (e.g. Escape, to close the player so it prints its summary).");
}

}  // namespace

int main(int argc, char** argv) {
  std::string prefix = "Panoptes", keys_arg = "Up,Down", out_path, final_key;
  int count = 40, timeout_ms = 2000;
  double gap_min = 150, gap_max = 450, threshold = 0.02;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) fail(a + " needs a value");
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else if (a == "--window") {
      prefix = next();
    } else if (a == "--keys") {
      keys_arg = next();
    } else if (a == "--count") {
      count = std::atoi(next().c_str());
    } else if (a == "--gap-ms") {
      const auto v = split(next(), ',');
      gap_min = std::atof(v[0].c_str());
      gap_max = v.size() > 1 ? std::atof(v[1].c_str()) : gap_min;
    } else if (a == "--threshold") {
      threshold = std::atof(next().c_str());
    } else if (a == "--timeout-ms") {
      timeout_ms = std::atoi(next().c_str());
    } else if (a == "--final-key") {
      final_key = next();
    } else if (a == "--out") {
      out_path = next();
    } else {
      fail("unknown option \"" + a + "\" (see --help)");
    }
  }
  if (count < 1 || gap_min < 0 || gap_max < gap_min) fail("--count must be >= 1 and --gap-ms MIN,MAX with 0 <= MIN <= MAX");

  Display* dpy = XOpenDisplay(nullptr);
  if (!dpy) fail("cannot open the X display (DISPLAY unset?)");
  int ev = 0, er = 0, maj = 0, min = 0;
  if (!XTestQueryExtension(dpy, &ev, &er, &maj, &min)) fail("the X server has no XTest extension");

  Window win = 0;
  for (int tries = 0; tries < 200 && !win; ++tries) {
    win = find_window(dpy, DefaultRootWindow(dpy), prefix);
    if (!win) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (!win) fail("no mapped window titled \"" + prefix + "...\" within 10 s");
  XWindowAttributes attr{};
  XGetWindowAttributes(dpy, win, &attr);
  int rx = 0, ry = 0;
  Window child = 0;
  XTranslateCoordinates(dpy, win, DefaultRootWindow(dpy), 0, 0, &rx, &ry, &child);

  std::vector<KeyCode> codes;
  const auto names = split(keys_arg, ',');
  for (const auto& k : names) {
    const KeySym sym = XStringToKeysym(k.c_str());
    if (sym == NoSymbol) fail("unknown key name \"" + k + "\" (X keysym names: Up, Down, Tab, c, ...)");
    codes.push_back(XKeysymToKeycode(dpy, sym));
  }

  // Pointer over the picture (no window manager: the focus follows the pointer), then the focus.
  XTestFakeMotionEvent(dpy, -1, rx + attr.width / 4, ry + attr.height / 2, CurrentTime);
  XSetInputFocus(dpy, win, RevertToParent, CurrentTime);
  XSync(dpy, False);

  Sampler s{dpy, win, attr.width / 50, attr.width * 6 / 10, {}};
  for (int r = 0; r < 24; ++r) s.rows.push_back(attr.height * 12 / 100 + r * (attr.height * 58 / 100) / 23);

  std::FILE* out = out_path.empty() ? stdout : std::fopen(out_path.c_str(), "w");
  if (!out) fail("cannot write " + out_path);
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> gap(gap_min, gap_max);
  std::vector<double> poll_ms;
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // let the window settle after the motion
  for (int i = 0; i < count; ++i) {
    const std::size_t k = std::size_t(i) % codes.size();
    const auto ref = s.grab();
    // The key's time is taken before it is sent: a probe descheduled between sending and reading the
    // clock would otherwise date the key late. The send's own duration is printed so such samples show.
    const double t_send = mono_ms();
    XTestFakeKeyEvent(dpy, codes[k], True, CurrentTime);
    XTestFakeKeyEvent(dpy, codes[k], False, CurrentTime);
    XFlush(dpy);
    const double t_sent = mono_ms();
    double t_change = -1, frac = 0, prev = t_sent, gap_at_change = 0;
    while (mono_ms() - t_send < timeout_ms) {
      const auto now = s.grab();
      const double t = mono_ms();
      poll_ms.push_back(t - prev);
      frac = changed_fraction(ref, now, 24);
      if (frac > threshold) {
        t_change = (prev + t) / 2;  // the change happened between the previous poll and this one
        gap_at_change = t - prev;
        break;
      }
      prev = t;
    }
    std::fprintf(out, "%d\t%s\t%.3f\t%.3f\t%.3f\t%.4f\t%.3f\t%.3f\n", i, names[k].c_str(), t_send, t_change,
                 t_change < 0 ? -1.0 : t_change - t_send, t_change < 0 ? 0.0 : frac, t_sent - t_send, gap_at_change);
    std::fflush(out);
    std::this_thread::sleep_for(std::chrono::microseconds(long(gap(rng) * 1000)));
  }
  if (!final_key.empty()) {
    const KeySym sym = XStringToKeysym(final_key.c_str());
    if (sym == NoSymbol) fail("unknown key name \"" + final_key + "\"");
    XTestFakeKeyEvent(dpy, XKeysymToKeycode(dpy, sym), True, CurrentTime);
    XTestFakeKeyEvent(dpy, XKeysymToKeycode(dpy, sym), False, CurrentTime);
    XSync(dpy, False);
  }
  std::sort(poll_ms.begin(), poll_ms.end());
  if (!poll_ms.empty())
    std::fprintf(stderr, "key_pixels_probe: %d keys, poll period p50 %.2f ms, p99 %.2f ms\n", count,
                 poll_ms[poll_ms.size() / 2], poll_ms[std::min(poll_ms.size() - 1, poll_ms.size() * 99 / 100)]);
  if (out != stdout) std::fclose(out);
  XCloseDisplay(dpy);
  return 0;
}
