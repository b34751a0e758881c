// Plain C++ Verilator harness for the bare x-processor array (no Python in the clock
// loop). Plays a 48-bit instruction stream (.de48, docs/formats.md) through de_array,
// one instruction per clock, collects the pixels that leave the last PE and writes a
// raw frame (.depx: "DEPX", u32 width, u32 height, then u16 little-endian pixels),
// which `diffengine` converts to PNG. Prints simulated cycles per second.
// A command file (.cmd text or .de32) is assembled first by `diffengine asm` (once,
// before the clock loop).
//
// docs/simulation.md is the manual: cycle and line numbering, the windows, the trace
// CSV columns, the breakpoints and their exit status (3).
//
//   array_harness IN.(de48|cmd|de32) OUT.depx [--width N] [--repeat K] [--quiet]
//       [--trace-pixels] [--list-ops]
//     trace-enabled builds (make -C sim harness TRACE=1) also take:
//       [--from-cycle C] [--to-cycle C] | [--line L]        the window
//       [--fst FILE.fst [--col Q]]                          FST of the window + FILE.gtkw
//       [--trace-pes LIST --trace-csv FILE|-]               per-PE state per cycle
//       [--break-cycle C | --break-line L | --break-pe P --break-op OP]
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include "de_isa.h"
#include "de_verilated.h"
#include <vector>

#include "Vde_array.h"
#include "verilated.h"
#ifdef DE_TRACE
#include "verilated_fst_c.h"
#include "verilated_syms.h"
#include <map>
#ifdef DE_FASTFWD
#include "Vde_array__Syms.h"
#include "Vde_array___024root.h"
#include "de_fast.h"
#endif
#endif

namespace {

constexpr int kExitBreak = 3;   // a breakpoint stopped the run
constexpr uint16_t kRefresh = DE_ID_REFRESH;
constexpr int kPixLatency = 3;  // docs/array.md: exit(q) = R + NumChips + 3 + q
constexpr int kPePerChip = 9;

struct Instr {
  uint16_t ident;
  uint64_t data;
};

bool read_de48(const std::string& path, std::vector<Instr>& out, std::string& err) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) {
    err = path + ": cannot open";
    return false;
  }
  unsigned char hdr[8];
  if (std::fread(hdr, 1, 8, f) != 8 || std::memcmp(hdr, "DE48", 4) != 0) {
    err = path + ": not a DE48 instruction stream (bad header)";
    std::fclose(f);
    return false;
  }
  unsigned char w[DE_RECORD_BITS / 8];
  size_t n;
  while ((n = std::fread(w, 1, sizeof w, f)) == sizeof w) {
    uint64_t v = 0;
    for (unsigned char b : w) v = (v << 8) | b;
    out.push_back({static_cast<uint16_t>(v >> DE_WORD_BITS), v & DE_WORD_MASK});
  }
  std::fclose(f);
  if (n != 0) {
    err = path + ": truncated instruction at byte " + std::to_string(8 + 6 * out.size());
    return false;
  }
  return true;
}

bool is_de48(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return true;  // let read_de48 report it
  char hdr[4] = {0, 0, 0, 0};
  const size_t n = std::fread(hdr, 1, 4, f);
  std::fclose(f);
  return n == 4 && std::memcmp(hdr, "DE48", 4) == 0;
}

// Repository root: DE_ROOT, else four levels above the executable
// (<root>/sim/build/<config>/Vde_array).
std::string repo_root() {
  if (const char* r = std::getenv("DE_ROOT")) return r;
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return ".";
  std::string p(buf, static_cast<size_t>(n));
  for (int i = 0; i < 4; ++i) p = p.substr(0, p.rfind('/'));
  return p;
}

// A .cmd text or .de32 frame store: `diffengine asm` turns it into a .de48 first.
bool assemble(const std::string& in, std::string& out, std::string& err) {
  char tmpl[] = "/tmp/array_harness_XXXXXX";
  const int fd = mkstemp(tmpl);
  if (fd < 0) {
    err = "cannot create a temporary file";
    return false;
  }
  close(fd);
  out = tmpl;
  const std::string root = repo_root();
  const std::string log = out + ".log";
  const pid_t pid = fork();
  if (pid == 0) {
    // Its messages go to a log, shown only when it fails.
    FILE* lf = std::fopen(log.c_str(), "w");
    if (lf) dup2(fileno(lf), 2);
    const std::string py = root + "/.venv/bin/python";
    const std::string pp = root + "/sw";
    setenv("PYTHONPATH", pp.c_str(), 1);
    const char* code = "import sys; from diffengine.cli import main; sys.exit(main(sys.argv[1:]))";
    execl(py.c_str(), py.c_str(), "-c", code, "asm", in.c_str(), "-o", out.c_str(),
          static_cast<char*>(nullptr));
    execlp("python3", "python3", "-c", code, "asm", in.c_str(), "-o", out.c_str(),
           static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (!ok) {
    err = in + ": `diffengine asm` failed";
    if (FILE* lf = std::fopen(log.c_str(), "r")) {
      char line[512];
      while (std::fgets(line, sizeof line, lf)) err += std::string("\n  ") + line;
      std::fclose(lf);
    }
  }
  std::remove(log.c_str());
  return ok;
}

bool parse_num(const char* s, long long& v) {
  char* end = nullptr;
  v = std::strtoll(s, &end, 0);
  return end && *end == '\0' && end != s;
}

// "0,5,17-19" or "all" -> sorted unique list of PEs below n_pe.
bool parse_pe_list(const std::string& spec, int n_pe, std::vector<int>& out,
                   std::string& err) {
  std::vector<char> want(static_cast<size_t>(n_pe), 0);
  if (spec == "all") {
    for (int p = 0; p < n_pe; ++p) want[p] = 1;
  } else {
    size_t pos = 0;
    while (pos <= spec.size()) {
      size_t comma = spec.find(',', pos);
      if (comma == std::string::npos) comma = spec.size();
      const std::string item = spec.substr(pos, comma - pos);
      long long lo, hi;
      const size_t dash = item.find('-', 1);
      bool ok = dash == std::string::npos
                    ? parse_num(item.c_str(), lo) && (hi = lo, true)
                    : parse_num(item.substr(0, dash).c_str(), lo) &&
                          parse_num(item.substr(dash + 1).c_str(), hi);
      if (!ok || lo < 0 || hi < lo || hi >= n_pe) {
        err = "PE list item '" + item + "' is not a PE or range within 0.." +
              std::to_string(n_pe - 1);
        return false;
      }
      for (long long p = lo; p <= hi; ++p) want[static_cast<size_t>(p)] = 1;
      pos = comma + 1;
    }
  }
  for (int p = 0; p < n_pe; ++p)
    if (want[p]) out.push_back(p);
  return true;
}

bool parse_op(const char* s, int& ident) {
  // The identifiers by their look-up table names (de_isa.h, from spec/isa.toml).
  for (unsigned c = 0; c < DE_LUT_ENTRIES; ++c)
    if (!strcasecmp(s, de_lut_name(c))) {
      ident = static_cast<int>(de_lut_ident(c));
      return true;
    }
  long long v;
  if (parse_num(s, v) && v >= 0 && v <= DE_ID_MASK) {
    ident = static_cast<int>(v);
    return true;
  }
  return false;
}

// The stream as the clock loop plays it: the input with Nops inserted so that two
// Refreshes are at least n_pe cycles apart (one Refresh active at a time, 7.4.1; the
// access controller's fixed line period does this in the real system), then Nops to
// drain the array. Cycle c of one play is seq[c].
std::vector<Instr> pad_stream(const std::vector<Instr>& prog, int n_pe, uint64_t& nops) {
  std::vector<Instr> seq;
  seq.reserve(prog.size() + 64);
  uint64_t since_refresh = static_cast<uint64_t>(n_pe);
  nops = 0;
  for (const Instr& in : prog) {
    if (in.ident == kRefresh)
      for (; since_refresh < static_cast<uint64_t>(n_pe); ++since_refresh, ++nops)
        seq.push_back({0, 0});
    seq.push_back(in);
    since_refresh = in.ident == kRefresh ? 1 : since_refresh + 1;
  }
  const size_t drain = static_cast<size_t>(n_pe) * 2 + 64;
  seq.insert(seq.end(), drain, Instr{0, 0});
  return seq;
}

struct Options {
  int width = 0, repeat = 1;
  bool quiet = false, trace_pixels = false, list_ops = false, no_ffwd = false;
  long long from = -1, to = -1, line = -1;
  std::string fst, pes_spec, csv;
  long long col = -1;
  long long break_cycle = -1, break_line = -1, break_pe = -1;
  int break_op = -1;
  bool tracing() const {
    return !fst.empty() || !csv.empty() || break_cycle >= 0 || break_line >= 0 ||
           break_pe >= 0;
  }
};

#ifdef DE_TRACE
// ---- per-PE state, read from the Verilated model's public signals -----------------
struct Sig {
  void* p = nullptr;
  VerilatedVarType t = VLVT_UNKNOWN;
  uint64_t get() const {
    switch (t) {
      case VLVT_UINT8: return *static_cast<const CData*>(p);
      case VLVT_UINT16: return *static_cast<const SData*>(p);
      case VLVT_UINT32: return *static_cast<const IData*>(p);
      case VLVT_UINT64: return *static_cast<const QData*>(p);
      default: return 0;
    }
  }
};

const VerilatedScope* find_scope(const std::string& name) {
  const VerilatedScope* s = Verilated::scopeFind(("TOP." + name).c_str());
  return s ? s : Verilated::scopeFind(name.c_str());
}

bool bind(const VerilatedScope* s, const char* var, Sig& out, std::string& err) {
  VerilatedVar* v = s ? s->varFind(var) : nullptr;
  if (!v || v->vltype() == VLVT_WDATA || v->vltype() == VLVT_UNKNOWN) {
    err = std::string("no public signal ") + (s ? s->name() : "?") + "." + var;
    return false;
  }
  out.p = v->datap();
  out.t = v->vltype();
  return true;
}

std::string pe_scope(int p) {
  return "de_array.g_chip[" + std::to_string(p / kPePerChip) + "].u_chip.u_core.g_pe[" +
         std::to_string(p % kPePerChip) + "].u_pe";
}

// The registers of one PE, in trace-CSV column order (docs/simulation.md).
const char* const kRegNames[] = {
    "a_q", "b_q", "c_q", "d_q", "pa_q", "pb_q", "pc_q", "dis_q", "lock_q", "accm_q",
    "act_q", "id_q", "id2_q", "out_q", "c1_q", "c2_q", "accc2_q", "accc3_q", "xz1_q",
    "act1_q", "prot1_q", "act2_q", "prot2_q", "e0wr2_q", "accen2_q", "accen3_q",
    "pixv_q", "pix_q"};
constexpr int kNumRegs = sizeof kRegNames / sizeof kRegNames[0];

struct PeProbe {
  int pe;
  Sig reg[kNumRegs];
  Sig in_id, in_data;  // upstream registers (PE p-1 or the chip boundary); PE 0: none
  Sig skew1, skew2;    // PE 0 only: de_skew's block-1 and block-2 delay lines
};

bool make_probe(int p, PeProbe& pr, std::string& err) {
  pr.pe = p;
  const VerilatedScope* s = find_scope(pe_scope(p));
  if (!s) {
    err = "no scope " + pe_scope(p) + " (is this a TRACE=1 build?)";
    return false;
  }
  for (int i = 0; i < kNumRegs; ++i)
    if (!bind(s, kRegNames[i], pr.reg[i], err)) return false;
  if (p == 0) {
    // de_skew's delay lines (rtl/prim/de_delay.sv): block j's registers, newest first.
    return bind(find_scope("de_array.u_skew.g_blk[1].u_delay.g_regs"), "stage_q", pr.skew1, err) &&
           bind(find_scope("de_array.u_skew.g_blk[2].u_delay.g_regs"), "stage_q", pr.skew2, err);
  }
  if (p % kPePerChip) {
    const VerilatedScope* up = find_scope(pe_scope(p - 1));
    return bind(up, "id_q", pr.in_id, err) && bind(up, "out_q", pr.in_data, err);
  }
  const VerilatedScope* chip =
      find_scope("de_array.g_chip[" + std::to_string(p / kPePerChip - 1) + "].u_chip.u_bound");
  return bind(chip, "id_q", pr.in_id, err) && bind(chip, "data_q", pr.in_data, err);
}

// One row: cycle,pe,ident,data,A,B,C,D,flags,id1,id2,out,c1,c2,accc2,accc3,xz1,act1,
// prot1,act2,prot2,e0wr2,accen2,accen3,pix_valid,pix,line
std::string state_row(uint64_t cycle, const PeProbe& pr, const Instr& in0, long long line) {
  uint64_t v[kNumRegs];
  for (int i = 0; i < kNumRegs; ++i) v[i] = pr.reg[i].get();
  uint64_t id, data;
  if (pr.pe == 0) {
    id = in0.ident;
    data = (in0.data & DE_BLOCK_MASK) | (pr.skew1.get() << DE_BLOCK_BITS) |
           (((pr.skew2.get() >> DE_BLOCK_BITS) & DE_BLOCK_MASK) << (2 * DE_BLOCK_BITS));
  } else {
    id = pr.in_id.get();
    data = pr.in_data.get();
  }
  char flags[8];
  const char letters[] = "ABCdlma";
  for (int i = 0; i < 7; ++i) flags[i] = v[4 + i] ? letters[i] : '.';
  flags[7] = '\0';
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%llu,%d,%03llx,%09llx,%09llx,%09llx,%09llx,%09llx,%s,%03llx,%03llx,%09llx,"
                "%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%03llx,%lld",
                static_cast<unsigned long long>(cycle), pr.pe,
                static_cast<unsigned long long>(id), static_cast<unsigned long long>(data),
                static_cast<unsigned long long>(v[0]), static_cast<unsigned long long>(v[1]),
                static_cast<unsigned long long>(v[2]), static_cast<unsigned long long>(v[3]),
                flags, static_cast<unsigned long long>(v[11]),
                static_cast<unsigned long long>(v[12]), static_cast<unsigned long long>(v[13]),
                static_cast<unsigned long long>(v[14]), static_cast<unsigned long long>(v[15]),
                static_cast<unsigned long long>(v[16]), static_cast<unsigned long long>(v[17]),
                static_cast<unsigned long long>(v[18]), static_cast<unsigned long long>(v[19]),
                static_cast<unsigned long long>(v[20]), static_cast<unsigned long long>(v[21]),
                static_cast<unsigned long long>(v[22]), static_cast<unsigned long long>(v[23]),
                static_cast<unsigned long long>(v[24]), static_cast<unsigned long long>(v[25]),
                static_cast<unsigned long long>(v[26]), static_cast<unsigned long long>(v[27]),
                line);
  return buf;
}

const char* const kCsvHeader =
    "cycle,pe,ident,data,A,B,C,D,flags,id1,id2,out,c1,c2,accc2,accc3,xz1,act1,prot1,"
    "act2,prot2,e0wr2,accen2,accen3,pix_valid,pix,line";

// GTKWave save file for the PEs `pes` (names as Verilator's FST writer spells them).
bool write_gtkw(const std::string& fst, const std::vector<int>& pes, uint64_t t0,
                std::string& err) {
  std::string path = fst;
  if (path.size() > 4 && path.compare(path.size() - 4, 4, ".fst") == 0)
    path.resize(path.size() - 4);
  path += ".gtkw";
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    err = path + ": cannot write";
    return false;
  }
  char cwd[4096];
  std::string abs = fst;
  if (fst[0] != '/' && getcwd(cwd, sizeof cwd)) abs = std::string(cwd) + "/" + fst;
  // Signal widths from de_isa.h: identifier, data word, pixel (= one block).
  const int idm = DE_ID_BITS - 1, wm = DE_WORD_BITS - 1, bm = DE_BLOCK_BITS - 1;
  std::fprintf(f, "[dumpfile] \"%s\"\n[timestart] %llu\n[size] 1800 1000\n"
               "[sst_expanded] 0\n@28\nTOP.clk_i\n@22\nTOP.id_i[%d:0]\nTOP.data_i[%d:0]\n"
               "@28\nTOP.pix_valid_o\n@22\nTOP.pix_o[%d:0]\n",
               abs.c_str(), static_cast<unsigned long long>(t0), idm, wm, bm);
  for (int p : pes) {
    const std::string s = "TOP." + pe_scope(p) + ".";
    std::fprintf(f, "-PE %d (chip %d, PE %d): identifier and skewed data in\n@22\n%sid_i[%d:0]\n"
                 "%sdata_i[%d:0]\n", p, p / kPePerChip, p % kPePerChip, s.c_str(), idm, s.c_str(), wm);
    std::fprintf(f, "-PE %d registers A-D as 12-bit blocks ([2] = integer part)\n", p);
    for (const char* r : {"a_q", "b_q", "c_q", "d_q"})
      for (int j = DE_BLOCKS - 1; j >= 0; --j)
        std::fprintf(f, "%s%s.%s[%d][%d:0]\n", s.c_str(), r, r, j, bm);
    std::fprintf(f, "-PE %d block carries: c1 (0->1), c2 (1->2); ACC accc2, accc3\n@28\n", p);
    for (const char* r : {"c1_q", "c2_q", "accc2_q", "accc3_q", "accen2_q", "accen3_q"})
      std::fprintf(f, "%s%s\n", s.c_str(), r);
    std::fprintf(f, "-PE %d protect / disable / lock / acc_mode / act\n", p);
    for (const char* r : {"pa_q", "pb_q", "pc_q", "dis_q", "lock_q", "accm_q", "act_q"})
      std::fprintf(f, "%s%s\n", s.c_str(), r);
    std::fprintf(f, "-PE %d data passed on, pixel out\n@22\n%sout_q.out_q[2][11:0]\n"
                 "%sout_q.out_q[1][11:0]\n%sout_q.out_q[0][11:0]\n@28\n%spix_valid_o\n@22\n"
                 "%spix_o[11:0]\n",
                 p, s.c_str(), s.c_str(), s.c_str(), s.c_str(), s.c_str());
  }
  std::fclose(f);
  return true;
}
#endif

#if defined(DE_TRACE) && defined(DE_FASTFWD)
// ---- fast-forward: run the fast array (sim/fast) up to the window, then hand its state to
// this traced flat model (docs/simulation.md section 7.5) -----------------------------------
// The flat scope of a register -> the piece scope that holds the same RTL instance:
//   TOP.de_array.u_skew...                  head.de_fast_head.u_skew...
//   TOP.de_array.g_chip[c].u_chip.u_core... c = 0: head...u_core...; else chip<c>...u_core...
//   TOP.de_array.g_chip[c].u_chip.u_bound.. c = N-1: tail...u_bound...; else chip<c+1>...u_bound...
//   TOP.de_array.u_deskew...                tail.de_fast_tail.u_deskew...
//   TOP.de_array: coll_q                    tail.de_fast_tail
//   TOP.de_array: skew_blk1z_q              head.de_fast_head (chip 0's block-1 zero flag)
// Anything else in the flat model is wiring between those instances, recomputed by the
// settle that follows.
bool piece_of(const std::string& flat, int n_chips, std::string& key, bool& top_scope) {
  static const std::string top = "TOP.de_array";
  top_scope = false;
  if (flat.compare(0, top.size(), top) != 0) return false;
  const std::string rest = flat.substr(top.size());
  if (rest.empty()) {
    // de_array's own registers live in two pieces: the key is chosen per register.
    top_scope = true;
    return true;
  }
  if (rest.compare(0, 7, ".u_skew") == 0) return key = "head" + rest, true;
  if (rest.compare(0, 9, ".u_deskew") == 0) return key = "tail" + rest, true;
  if (rest.compare(0, 8, ".g_chip[") != 0) return false;
  const size_t close = rest.find(']');
  const int c = std::atoi(rest.c_str() + 8);
  const std::string r2 = rest.substr(close + 1);  // ".u_chip..."
  if (r2.compare(0, 14, ".u_chip.u_core") == 0) {
    key = (c == 0 ? std::string("head") : "chip" + std::to_string(c)) + r2.substr(7);
    return true;
  }
  if (r2.compare(0, 15, ".u_chip.u_bound") == 0) {
    key = (c == n_chips - 1 ? std::string("tail") : "chip" + std::to_string(c + 1)) +
          r2.substr(7);
    return true;
  }
  return false;
}

bool is_register(const std::string& name) {
  const size_t n = name.size();
  return (n > 2 && name.compare(n - 2, 2, "_q") == 0) ||
         (n > 3 && name.compare(n - 3, 3, "_q2") == 0);
}

// Copies every register (the *_q / *_q2 variables, public in both models) between the
// fast array and this model, in the direction asked, then settles the receiver's wiring
// as on its first evaluation. A register of a mapped flat scope without a twin in its
// piece is an error, not a skip.
bool hand_over(de_fast::Array& fa, VerilatedContext& flat_ctx, Vde_array& top, int n_chips,
               bool to_flat, long& copied, std::string& err) {
  std::map<std::string, const VerilatedScope*> pieces;  // "chip5.u_core.g_pe[0].u_pe" -> scope
  for (const auto& kv : *fa.context()->scopeNameMap()) {
    const std::string n = kv.first;  // "<model>.de_fast_<kind><rest>"
    const size_t dot = n.find('.');
    if (dot == std::string::npos) continue;
    if (n.compare(dot + 1, 8, "de_fast_") != 0) continue;  // e.g. the de_pkg scope
    const size_t dot2 = n.find('.', dot + 1);
    pieces[n.substr(0, dot) + (dot2 == std::string::npos ? "" : n.substr(dot2))] = kv.second;
  }
  copied = 0;
  for (const auto& kv : *flat_ctx.scopeNameMap()) {
    std::string key;
    bool top_scope = false;
    if (!piece_of(kv.first, n_chips, key, top_scope)) continue;
    const VerilatedVarNameMap* vars = kv.second->varsp();
    if (!vars) continue;
    for (const auto& v : *vars) {
      const std::string name = v.first;
      if (!is_register(name)) continue;
      VerilatedVar* fv = kv.second->varFind(name.c_str());
      if (fv->isParam() || !fv->datap()) continue;
      // A register of de_array itself: the collision flag is the tail's, chip 0's zero
      // flag of block 1 (registered beside de_skew) the head's; any other one has no twin
      // and is reported below.
      if (top_scope) key = name == "skew_blk1z_q" ? "head" : "tail";
      const auto it = pieces.find(key);
      VerilatedVar* pv = it == pieces.end() ? nullptr : it->second->varFind(name.c_str());
      if (!pv || pv->totalSize() != fv->totalSize()) {
        err = std::string("fast-forward: register ") + kv.first + "." + name +
              " has no twin in piece scope " + key;
        return false;
      }
      if (to_flat) std::memcpy(fv->datap(), pv->datap(), fv->totalSize());
      else std::memcpy(pv->datap(), fv->datap(), fv->totalSize());
      ++copied;
    }
  }
  if (to_flat) {
    // Settle the wiring from the registers: the model evaluates as on its first call
    // (initial + settle; the RTL has no initial blocks, registers are set at construction).
    top.rootp->vlSymsp->__Vm_didInit = false;
    top.eval();
  } else {
    fa.settle();
  }
  return true;
}
#endif

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: %s IN.(de48|cmd|de32) OUT.depx [--width N] [--repeat K] [--quiet]\n"
                 "  [--trace-pixels] [--list-ops] [--from-cycle C] [--to-cycle C] [--line L]\n"
                 "  [--fst FILE.fst] [--col Q] [--trace-pes LIST] [--trace-csv FILE|-]\n"
                 "  [--break-cycle C] [--break-line L] [--break-pe P --break-op OP]\n"
                 "  [--no-fast-forward]\n",
                 argv[0]);
    return 2;
  }
  Options o;
  for (int i = 3; i < argc; ++i) {
    const char* a = argv[i];
    const bool has = i + 1 < argc;
    long long v = 0;
    auto num = [&](long long& dst) {
      if (!has || !parse_num(argv[i + 1], v) || v < 0) {
        std::fprintf(stderr, "%s: %s wants a number >= 0\n", argv[0], a);
        std::exit(2);
      }
      dst = v;
      ++i;
    };
    auto str = [&](std::string& dst) {
      if (!has) {
        std::fprintf(stderr, "%s: %s wants an argument\n", argv[0], a);
        std::exit(2);
      }
      dst = argv[++i];
    };
    long long tmp;
    if (!std::strcmp(a, "--width")) num(tmp), o.width = static_cast<int>(tmp);
    else if (!std::strcmp(a, "--repeat")) num(tmp), o.repeat = static_cast<int>(tmp);
    else if (!std::strcmp(a, "--quiet")) o.quiet = true;
    else if (!std::strcmp(a, "--trace-pixels")) o.trace_pixels = true;
    else if (!std::strcmp(a, "--list-ops")) o.list_ops = true;
    else if (!std::strcmp(a, "--no-fast-forward")) o.no_ffwd = true;
    else if (!std::strcmp(a, "--from-cycle")) num(o.from);
    else if (!std::strcmp(a, "--to-cycle")) num(o.to);
    else if (!std::strcmp(a, "--line")) num(o.line);
    else if (!std::strcmp(a, "--fst")) str(o.fst);
    else if (!std::strcmp(a, "--col")) num(o.col);
    else if (!std::strcmp(a, "--trace-pes")) str(o.pes_spec);
    else if (!std::strcmp(a, "--trace-csv")) str(o.csv);
    else if (!std::strcmp(a, "--break-cycle")) num(o.break_cycle);
    else if (!std::strcmp(a, "--break-line")) num(o.break_line);
    else if (!std::strcmp(a, "--break-pe")) num(o.break_pe);
    else if (!std::strcmp(a, "--break-op")) {
      if (!has || !parse_op(argv[i + 1], o.break_op)) {
        std::fprintf(stderr, "%s: --break-op wants a mnemonic (--list-ops) or an "
                     "identifier 0..0xfff\n", argv[0]);
        return 2;
      }
      ++i;
    } else {
      std::fprintf(stderr, "%s: unknown option %s\n", argv[0], a);
      return 2;
    }
  }
  if (o.list_ops) {
    for (unsigned c = 0; c < DE_LUT_ENTRIES; ++c)
      std::printf("%s 0x%03x\n", de_lut_name(c), de_lut_ident(c));
    return 0;
  }
  if (o.repeat < 1) o.repeat = 1;
  if ((o.break_pe >= 0) != (o.break_op >= 0)) {
    std::fprintf(stderr, "%s: --break-pe and --break-op go together\n", argv[0]);
    return 2;
  }
  if (o.line >= 0 && (o.from >= 0 || o.to >= 0)) {
    std::fprintf(stderr, "%s: --line and --from-cycle/--to-cycle exclude each other\n",
                 argv[0]);
    return 2;
  }
  if (!o.csv.empty() && o.pes_spec.empty()) {
    std::fprintf(stderr, "%s: --trace-csv needs --trace-pes\n", argv[0]);
    return 2;
  }
#ifndef DE_TRACE
  if (o.tracing()) {
    std::fprintf(stderr, "%s: --fst, --trace-csv and the breakpoints need the trace build "
                 "(make -C sim harness TRACE=1)\n", argv[0]);
    return 2;
  }
#endif

  std::vector<Instr> prog;
  std::string err, in_path = argv[1], tmp_path;
  if (!is_de48(in_path)) {
    if (!assemble(in_path, tmp_path, err)) {
      std::fprintf(stderr, "%s\n", err.c_str());
      return 1;
    }
    in_path = tmp_path;
  }
  const bool read_ok = read_de48(in_path, prog, err);
  if (!tmp_path.empty()) std::remove(tmp_path.c_str());
  if (!read_ok) {
    std::fprintf(stderr, "%s\n", err.c_str());
    return 1;
  }
  auto ctx = std::make_unique<VerilatedContext>();
  ctx->commandArgs(1, argv);
#ifdef DE_TRACE
  ctx->traceEverOn(true);
#endif
  auto top = std::make_unique<Vde_array>(ctx.get());
  top->eval();
  const int n_pe = top->n_pe_o;  // the array reports its own column count
  if (n_pe <= 0) {
    std::fprintf(stderr, "%s: the array reports %d PEs\n", argv[0], n_pe);
    return 1;
  }
  const int n_chips = n_pe / kPePerChip;
  const int width = (o.width <= 0 || o.width > n_pe) ? n_pe : o.width;

  uint64_t nops_added = 0;
  const std::vector<Instr> seq = pad_stream(prog, n_pe, nops_added);
  const uint64_t play = seq.size();
  const uint64_t total = play * static_cast<uint64_t>(o.repeat);
  // Refresh cycles of every line of the whole run (all repeats), in order.
  std::vector<uint64_t> refresh_at;
  for (int r = 0; r < o.repeat; ++r)
    for (uint64_t c = 0; c < play; ++c)
      if (seq[c].ident == kRefresh) refresh_at.push_back(r * play + c);
  auto line_of_slot = [&](long long slot) -> long long {  // the line slot `slot` belongs to
    if (slot < 0) return 0;
    return std::lower_bound(refresh_at.begin(), refresh_at.end(),
                            static_cast<uint64_t>(slot)) - refresh_at.begin();
  };

  // The window: --line L = from the cycle Refresh L-1 is on id_i (cycle 0 for L = 0)
  // to the cycle line L's last pixel is on pix_o.
  uint64_t w_from = 0, w_to = total ? total - 1 : 0;
  if (o.line >= 0) {
    if (static_cast<uint64_t>(o.line) >= refresh_at.size()) {
      std::fprintf(stderr, "%s: --line %lld: the stream has lines 0..%lld\n", argv[0], o.line,
                   static_cast<long long>(refresh_at.size()) - 1);
      return 2;
    }
    w_from = o.line ? refresh_at[o.line - 1] : 0;
    w_to = refresh_at[o.line] + n_chips + kPixLatency + n_pe - 1;
  } else {
    if (o.from >= 0) w_from = static_cast<uint64_t>(o.from);
    if (o.to >= 0) w_to = static_cast<uint64_t>(o.to);
  }
  if (w_to >= total) w_to = total ? total - 1 : 0;
  if (w_from > w_to) {
    std::fprintf(stderr, "%s: empty window %llu..%llu\n", argv[0],
                 static_cast<unsigned long long>(w_from), static_cast<unsigned long long>(w_to));
    return 2;
  }
  uint64_t break_at = UINT64_MAX;
  if (o.break_cycle >= 0) break_at = static_cast<uint64_t>(o.break_cycle);
  if (o.break_line >= 0) {
    if (static_cast<uint64_t>(o.break_line) >= refresh_at.size()) {
      std::fprintf(stderr, "%s: --break-line %lld: the stream has lines 0..%lld\n", argv[0],
                   o.break_line, static_cast<long long>(refresh_at.size()) - 1);
      return 2;
    }
    // Line L starts when its first instruction is on id_i.
    const uint64_t c = o.break_line ? refresh_at[o.break_line - 1] + 1 : 0;
    break_at = std::min(break_at, c);
  }
  if (o.break_pe >= n_pe) {
    std::fprintf(stderr, "%s: --break-pe %lld: the array has PEs 0..%d\n", argv[0],
                 o.break_pe, n_pe - 1);
    return 2;
  }

#ifdef DE_TRACE
  std::vector<int> trace_pes;
  if (!o.pes_spec.empty() && !parse_pe_list(o.pes_spec, n_pe, trace_pes, err)) {
    std::fprintf(stderr, "%s: --trace-pes: %s\n", argv[0], err.c_str());
    return 2;
  }
  // PEs shown at a breakpoint: --trace-pes, else the break PE and its neighbours, else 0..2.
  std::vector<int> show = trace_pes;
  if (show.empty()) {
    const long long c = o.break_pe >= 0 ? o.break_pe : (o.col >= 0 ? o.col : 1);
    for (long long p = std::max(0LL, c - 1); p <= std::min<long long>(n_pe - 1, c + 1); ++p)
      show.push_back(static_cast<int>(p));
  }
  std::vector<int> probe_pes = show;
  if (o.break_pe >= 0) probe_pes.push_back(static_cast<int>(o.break_pe));
  std::vector<PeProbe> probes(probe_pes.size());
  for (size_t i = 0; i < probe_pes.size(); ++i)
    if (!make_probe(probe_pes[i], probes[i], err)) {
      std::fprintf(stderr, "%s: %s\n", argv[0], err.c_str());
      return 1;
    }
  const PeProbe* brk_probe = o.break_pe >= 0 ? &probes.back() : nullptr;
  FILE* csv = nullptr;
  if (!o.csv.empty()) {
    csv = o.csv == "-" ? stdout : std::fopen(o.csv.c_str(), "w");
    if (!csv) {
      std::fprintf(stderr, "%s: cannot write\n", o.csv.c_str());
      return 1;
    }
    std::fprintf(csv, "%s\n", kCsvHeader);
  }
  std::unique_ptr<VerilatedFstC> fst;
  std::vector<int> wave_pes;
  if (!o.fst.empty()) {
    const long long q = o.col >= 0 ? std::min<long long>(o.col, n_pe - 1) : 1;
    for (long long p = std::max(0LL, q - 1); p <= std::min<long long>(n_pe - 1, q + 1); ++p)
      wave_pes.push_back(static_cast<int>(p));
    fst = std::make_unique<VerilatedFstC>();
    // Only the top ports, the array level and the chips of the shown PEs are dumped
    // (a level of 0 would mean everything).
    fst->dumpvars(1, "TOP");
    fst->dumpvars(1, "TOP.de_array");
    for (int p : wave_pes)
      fst->dumpvars(99, "TOP.de_array.g_chip[" + std::to_string(p / kPePerChip) + "]");
    top->trace(fst.get(), 99);
  }
  auto state_of = [&](uint64_t c, const PeProbe& pr) {
    // The slot on this PE's input in cycle c entered the array at c - pe - chip.
    const long long slot = static_cast<long long>(c) - pr.pe - pr.pe / kPePerChip;
    return state_row(c, pr, seq[c % play], line_of_slot(slot));
  };
#endif

  auto tick = [&]() { de_sim::tick(*top); };
  top->rst_i = 1;
  top->id_i = 0;
  top->data_i = 0;
  de_sim::chains_idle(*top);
  for (int i = 0; i < 4; ++i) tick();
  top->rst_i = 0;

  std::vector<uint16_t> pixels;
  bool collided = false;
  const bool slow = o.tracing();
  auto t0 = std::chrono::steady_clock::now();
  uint64_t cycle = 0;
  uint64_t first_i = 0;  // where the first repeat starts in the flat model
#if defined(DE_TRACE) && defined(DE_FASTFWD)
  std::unique_ptr<de_fast::Array> fa;  // the fast array, while it holds the state
  // Slot k of the stream through the fast array: the pixel, its trace, the collision.
  auto fast_step = [&](uint64_t k) {
    de_fast::In in;
    in.ident = seq[k].ident;
    in.data = seq[k].data;
    const de_fast::Out fo = fa->step(in);
    if (fo.pixel_valid) pixels.push_back(fo.pixel);
    if (o.trace_pixels && fo.pixel_valid)
      std::printf("cycle %llu pixel %zu = %u\n", static_cast<unsigned long long>(k + 1),
                  pixels.size() - 1, fo.pixel);
    if (o.trace_pixels && seq[k].ident == kRefresh)
      std::printf("cycle %llu Refresh in\n", static_cast<unsigned long long>(k + 1));
    if (fo.collision && !collided) {
      collided = true;
      std::fprintf(stderr, "%s: pixel collision at cycle %llu\n", argv[1],
                   static_cast<unsigned long long>(k + 1));
    }
  };
  // Nothing is observed before the window (or the breakpoint cycle), so those cycles run
  // in the fast array; an opcode breakpoint watches every cycle and turns this off.
  uint64_t ffwd = (!o.fst.empty() || !o.csv.empty()) ? w_from : UINT64_MAX;
  ffwd = std::min(ffwd, break_at);
  if (ffwd == UINT64_MAX || o.no_ffwd || o.break_pe >= 0 || !slow) ffwd = 0;
  ffwd = std::min<uint64_t>(ffwd, play);
  if (ffwd > 0) {
    const auto f0 = std::chrono::steady_clock::now();
    fa = std::make_unique<de_fast::Array>(n_chips, kPePerChip,
                                          de_fast::Array::compiled_carry_bug());
    de_fast::In rin;
    rin.rst = true;
    for (int k = 0; k < 4; ++k) fa->step(rin);
    for (uint64_t i = 0; i < ffwd; ++i) fast_step(i);
    // The pieces made their own context the thread's current one. Make it the flat
    // model's again before anything can return: a Verilated scope unregisters from the
    // thread's current context when destroyed, so returning with a piece's context current
    // left ~Vde_array locking the mutex of a context already freed with the fast array
    // (the harness printed its error and hung instead of exiting).
    Verilated::threadContextp(ctx.get());
    long copied = 0;
    if (!hand_over(*fa, *ctx, *top, n_chips, true, copied, err)) {
      std::fprintf(stderr, "%s: %s\n", argv[0], err.c_str());
      return 1;
    }
    first_i = cycle = ffwd;
    std::fprintf(stderr, "harness: fast-forward %llu cycles in the fast array (%.2f s), %ld "
                 "variables handed to the traced model\n",
                 static_cast<unsigned long long>(ffwd),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - f0).count(),
                 copied);
  }
  Verilated::threadContextp(ctx.get());
  // After a window with nothing to watch beyond it, the rest runs in the fast array again.
  const uint64_t back_at = (fa && o.repeat == 1 && (!o.fst.empty() || !o.csv.empty()) &&
                            o.break_pe < 0 && break_at == UINT64_MAX && w_to + 1 < play)
                               ? w_to : UINT64_MAX;
  bool handed_back = false;
#endif
  for (int r = 0; r < o.repeat; ++r) {
    for (uint64_t i = r == 0 ? first_i : 0; i < play; ++i, ++cycle) {
      const Instr& in = seq[i];
      top->id_i = in.ident;
      top->data_i = in.data;
#ifdef DE_TRACE
      if (slow) {
        // Cycle c spans [10c, 10c+10) in the FST: inputs and registers of cycle c from
        // 10c (the rising edge that ends cycle c is at 10c+10), clock low from 10c+5.
        top->eval();
        const bool in_win = cycle >= w_from && cycle <= w_to;
        if (fst && cycle == w_from) {
          fst->open(o.fst.c_str());
        }
        if (fst && in_win) fst->dump(10 * cycle);
        if (csv && in_win)
          for (size_t k = 0; k < trace_pes.size(); ++k)
            std::fprintf(csv, "%s\n", state_of(cycle, probes[k]).c_str());
        bool stop = cycle == break_at;
        if (brk_probe && !stop) {
          const uint64_t id = brk_probe->pe == 0 ? in.ident : brk_probe->in_id.get();
          stop = id == static_cast<uint64_t>(o.break_op);
        }
        if (stop) {
          const long long line = line_of_slot(static_cast<long long>(cycle));
          std::printf("break: cycle %llu, line %lld (of the instruction on id_i)",
                      static_cast<unsigned long long>(cycle), line);
          if (brk_probe)
            std::printf(", PE %d (column %d) receives identifier 0x%03x",
                        brk_probe->pe, brk_probe->pe, o.break_op);
          std::printf("\n%s\n", kCsvHeader);
          for (size_t k = 0; k < show.size(); ++k)
            std::printf("%s\n", state_of(cycle, probes[k]).c_str());
          if (fst) {
            fst->close();
            if (!write_gtkw(o.fst, wave_pes, 10 * w_from, err))
              std::fprintf(stderr, "%s\n", err.c_str());
          }
          if (csv && csv != stdout) std::fclose(csv);
          std::fflush(stdout);
          top->final();
          return kExitBreak;
        }
        top->clk_i = 0;
        top->eval();
        if (fst && in_win) fst->dump(10 * cycle + 5);
        top->clk_i = 1;
        top->eval();
        if (fst && cycle == w_to) {
          fst->dump(10 * cycle + 10);
          fst->close();
        }
      } else {
        tick();
      }
#else
      tick();
#endif
      if (top->pix_valid_o && r == 0) pixels.push_back(top->pix_o);
      if (o.trace_pixels && top->pix_valid_o)
        std::printf("cycle %llu pixel %zu = %u\n", static_cast<unsigned long long>(cycle + 1),
                    pixels.size() - 1, top->pix_o);
      if (o.trace_pixels && in.ident == kRefresh)
        std::printf("cycle %llu Refresh in\n", static_cast<unsigned long long>(cycle + 1));
      if (top->pix_collision_o && !collided) {
        collided = true;
        std::fprintf(stderr, "%s: pixel collision at cycle %llu\n", argv[1],
                     static_cast<unsigned long long>(cycle + 1));
      }
#if defined(DE_TRACE) && defined(DE_FASTFWD)
      if (cycle == back_at) {
        const auto b0 = std::chrono::steady_clock::now();
        long copied = 0;
        if (!hand_over(*fa, *ctx, *top, n_chips, false, copied, err)) {
          std::fprintf(stderr, "%s: %s\n", argv[0], err.c_str());
          return 1;
        }
        Verilated::threadContextp(ctx.get());
        for (uint64_t k = i + 1; k < play; ++k) fast_step(k);
        handed_back = true;
        std::fprintf(stderr, "harness: after the window, %llu cycles back in the fast array "
                     "(%.2f s)\n", static_cast<unsigned long long>(play - i - 1),
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - b0)
                         .count());
        cycle = play - 1;
        break;
      }
#endif
    }
  }
  (void)slow;
  bool collision_at_end = top->pix_collision_o;
#if defined(DE_TRACE) && defined(DE_FASTFWD)
  if (handed_back) {
    ++cycle;  // the loop's own increment was skipped by the break
    collision_at_end = collided;
  }
#endif
  if (collision_at_end) {
    std::fprintf(stderr, "%s: pixel collision in the array (Refreshes too close)\n", argv[1]);
    return 1;
  }
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const uint32_t height = static_cast<uint32_t>(pixels.size() / n_pe);
  if (pixels.size() % n_pe) {
    std::fprintf(stderr, "%s: %zu pixels is not a whole number of %d-column lines\n",
                 argv[1], pixels.size(), n_pe);
    return 1;
  }
  FILE* f = std::fopen(argv[2], "wb");
  if (!f) {
    std::fprintf(stderr, "%s: cannot write\n", argv[2]);
    return 1;
  }
  const uint32_t w32 = static_cast<uint32_t>(width);
  std::fwrite("DEPX", 1, 4, f);
  std::fwrite(&w32, 4, 1, f);
  std::fwrite(&height, 4, 1, f);
  for (uint32_t y = 0; y < height; ++y)
    std::fwrite(&pixels[static_cast<size_t>(y) * n_pe], 2, width, f);
  std::fclose(f);
#ifdef DE_TRACE
  if (csv && csv != stdout) std::fclose(csv);
  if (fst) {
    if (!write_gtkw(o.fst, wave_pes, 10 * w_from, err)) {
      std::fprintf(stderr, "%s\n", err.c_str());
      return 1;
    }
    std::fprintf(stderr, "harness: fst %s cycles %llu..%llu (time %llu..%llu ns), PEs %d..%d\n",
                 o.fst.c_str(), static_cast<unsigned long long>(w_from),
                 static_cast<unsigned long long>(w_to),
                 static_cast<unsigned long long>(10 * w_from),
                 static_cast<unsigned long long>(10 * w_to + 10), wave_pes.front(),
                 wave_pes.back());
  }
#endif
  if (!o.quiet)
    std::printf("harness: %d PEs, %zu instructions x %d (+%llu Nops for Refresh spacing), "
                "%llu cycles in %.3f s = %.0f cycles/s, %u lines\n", n_pe, prog.size(),
                o.repeat, static_cast<unsigned long long>(nops_added),
                static_cast<unsigned long long>(cycle), secs, cycle / secs, height);
  top->final();
  return 0;
}
