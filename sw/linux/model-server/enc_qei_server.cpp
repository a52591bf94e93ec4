// SPDX-License-Identifier: Apache-2.0
// enc_qei_server -- a Verilator model of enc_qei_wb serving register accesses over a Unix socket,
// for the UML bridge of `make linux-test` (sw/linux/uml-bridge/enc_qei_bridge.c).
//
// Usage: enc_qei_server --socket PATH [--id WORD]
//
// The server listens on PATH and accepts two connections: the first carries requests, the second
// the interrupt. A request is four 32-bit words {op, addr, data, sel}; the answer two {data,
// status}. op 1 reads the register at byte address addr (one Wishbone access), op 2 writes data
// with byte enables sel, op 3 advances the encoders by data motion steps (sw/linux/stimulus.h:
// each step's inputs held for ENC_STIM_STEP_CLOCKS clocks). status is 1 when the peripheral
// answered with wb_err_o or not at all (see the bound below), or the address is outside its
// ADDR_W bits, else 0. After every request and before its answer, the server sends one byte on the
// interrupt connection if the irq output rose since the last one it reported.
//
// A build whose channels share one engine (CAPS.ENGINE = shared, rtl/enc_qei.rdl) shows a change
// later and lets a write act later, by bounds in clocks of P = 24 * max(CHANNELS, 2). The server
// keeps the motion clear of them, so that what every register shows after N motion steps is what
// a per_channel build shows: an advance starts with P + 22 idle clocks (a write answered before
// it acts by then: P + 14 after its answer for CTRL and the other registers the counting uses,
// P + 22 for EVENTS, IRQ_EN, COUNT_HI and the error counts) and ends, after the last step's
// ENC_STIM_STEP_CLOCKS, with P + 44 more (a change the per_channel build shows within the step
// shows by then, irq included). The steps keep their spacing: the engine's channels count in the
// clocks a per_channel build does.
//
// The RDL bounds the answer to an access: 2 clocks after its request on a per_channel build; on
// the shared engine 6 (a read 5, a write 4, a COUNT_LO write with some byte lanes 6, a COUNT_LO
// read of another channel 6), and an access of a channel waits until that channel's writes are
// stored: one right after a write is answered at most P + 66 clocks after the write's request
// (P + 68 after a COUNT_LO write with some byte lanes off, which the driver does not make).
// With COUNT_W > 32, a COUNT_LO read of another channel than the last COUNT_LO read's stores that
// channel's COUNT_HI latch (after that channel's write not stored yet: at most P + 63 clocks after
// that write's answer), and an access of that channel requested right after waits for the store:
// at most P + 23 clocks after that read's answer.
// The server holds every access to that bound, counted from the last write of the same 0x100-byte
// page (a channel); for a write that itself waited for an earlier one, from its answer less 6
// clocks, as if it had been requested then and not waited (the RDL states the bound for a write
// that did not wait). It names the first 8 answers later than that (with the access before),
// prints their count and the longest answer at exit, and gives up on an access after four times
// P + 66 clocks, plus 16 (a bus error, and a line "no answer").
//
// --id makes reads of ID answer WORD instead of the RTL's ID (the driver's refusal of a wrong ID
// or version is tested with it). The parameters of the build (CHANNELS, PROFILE, COUNT_W, TS_W,
// FUNC_MASK, ENGINE, ADDR_W) are Verilator -G options of the model;
// ENC_QEI_ADDR_W (a -D option) is the same ADDR_W.
// The server exits when the request connection closes.
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include "Venc_qei_wb.h"
#include "verilated.h"

extern "C" {
#include "stimulus.h"
}

namespace {

constexpr uint32_t kOpRead = 1, kOpWrite = 2, kOpAdvance = 3;
constexpr int kMaxChannels = 16;

Venc_qei_wb *top;
struct enc_stim stim[kMaxChannels];
int channels;
uint64_t clocks;
int answer_bound = 2;       // clocks from a request to its answer, at most, by the RDL (above)
int after_write_bound = 2;  // clocks from a write's request to the answer of the access after it
int longest_answer;         // the longest seen
uint64_t late_answers;      // answers later than answer_bound
uint32_t prev_addr;         // the access before (for the report of a late answer)
bool prev_we;
uint64_t prev_request;
constexpr int kPages = 64;  // 0x100-byte pages of the address space (a channel's registers)
uint64_t last_write[kPages];  // each page's last write: its request, or for a write that waited
                              // its answer less answer_bound
// COUNT_W > 32 on the shared engine with two channels or more: the COUNT_HI latch store (above)
bool save_rule;
int save_bound;               // P + 23
int save_read_bound;          // P + 63, from the write's request: P + 67
int latch_page = -1;          // the channel (page) whose COUNT_HI latch the engine holds
bool saved[kPages];           // a latch store was made for the page ...
uint64_t last_save[kPages];   // ... by the COUNT_LO read answered then
constexpr uint32_t kCountLo = 0x10;  // COUNT_LO's offset in a channel's page

void tick() {
    top->clk = 0;
    top->eval();
    top->clk = 1;
    top->eval();
    clocks++;
}

void drive_inputs() {
    uint32_t a = 0, b = 0, z = 0;
    for (int k = 0; k < channels; k++) {
        a |= enc_stim_a(stim[k].pos) << k;
        b |= enc_stim_b(stim[k].pos) << k;
        z |= enc_stim_z(stim[k].pos) << k;
    }
    top->a_in = a;
    top->b_in = b;
    top->z_in = z;
}

// One Wishbone access; returns the status (0 ack, 1 err) and the read data in *data.
uint32_t access(uint32_t addr, bool we, uint32_t *data, uint32_t sel) {
    const uint64_t request = clocks;
    uint64_t answered = request;
    const int page = addr >> 8 & (kPages - 1);
    // a COUNT_LO read of another channel than the latch's stores that channel's latch (above)
    const bool stores = save_rule && !we && (addr & 0xff) == kCountLo && page < channels &&
        latch_page >= 0 && latch_page != page;
    top->wb_adr_i = addr;
    top->wb_dat_i = *data;
    top->wb_sel_i = sel;
    top->wb_we_i = we;
    top->wb_cyc_i = 1;
    top->wb_stb_i = 1;
    top->eval();
    uint32_t status = 1;
    *data = 0;
    const int give_up = 4 * after_write_bound + 16;
    for (int i = 1; i <= give_up; i++) {
        tick();
        if (top->wb_ack_o || top->wb_err_o) {
            status = top->wb_err_o ? 1 : 0;
            *data = top->wb_dat_o;
            if (i > longest_answer)
                longest_answer = i;
            const uint64_t since_write = request + i - last_write[page];
            const bool after_save = saved[page] &&
                request + i - last_save[page] <= static_cast<uint64_t>(save_bound);
            // (a read that stores another channel's latch waits for that one's write)
            const bool after_other = stores &&
                request + i - last_write[latch_page] <= static_cast<uint64_t>(save_read_bound);
            const bool late = i > answer_bound &&
                since_write > static_cast<uint64_t>(after_write_bound) && !after_save && !after_other;
            answered = request + i;
            if (late && late_answers++ < 8)
                fprintf(stderr, "enc_qei_server: late answer: a %s of 0x%03x answered %d clocks "
                        "after its request (clock %llu), %llu after a %s of 0x%03x\n",
                        we ? "write" : "read", addr, i, static_cast<unsigned long long>(request),
                        static_cast<unsigned long long>(request - prev_request),
                        prev_we ? "write" : "read", prev_addr);
            break;
        }
    }
    if (!top->wb_ack_o && !top->wb_err_o)
        fprintf(stderr, "enc_qei_server: no answer to a %s of 0x%03x within %d clocks\n",
                we ? "write" : "read", addr, give_up);
    top->wb_cyc_i = 0;
    top->wb_stb_i = 0;
    tick();
    prev_addr = addr;
    prev_we = we;
    prev_request = request;
    if (stores) {
        saved[latch_page] = true;
        last_save[latch_page] = answered;
    }
    if (save_rule && !we && (addr & 0xff) == kCountLo && page < channels)
        latch_page = page;  // (the latch is this channel's from now)
    // a write that waited itself counts from its answer less answer_bound (see the top)
    if (we)
        last_write[addr >> 8 & (kPages - 1)] =
            clocks - 1 - answer_bound > request ? clocks - 1 - answer_bound : request;
    return status;
}

bool full_io(int fd, void *buf, size_t len, bool rd) {
    char *p = static_cast<char *>(buf);
    while (len) {
        ssize_t n = rd ? read(fd, p, len) : write(fd, p, len);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return false;
        p += n;
        len -= static_cast<size_t>(n);
    }
    return true;
}

int usage(const char *msg) {
    fprintf(stderr, "enc_qei_server: %s\nusage: enc_qei_server --socket PATH [--id WORD]\n", msg);
    return 2;
}

}  // namespace

int main(int argc, char **argv) {
    const char *path = nullptr;
    bool id_override = false;
    uint32_t id_word = 0;
    for (int i = 1; i < argc; i++) {
        std::string arg = argv[i];
        if (arg == "--socket" && i + 1 < argc) {
            path = argv[++i];
        } else if (arg == "--id" && i + 1 < argc) {
            char *end;
            id_word = static_cast<uint32_t>(strtoul(argv[++i], &end, 0));
            if (*end)
                return usage("--id takes a number");
            id_override = true;
        } else {
            return usage(("unknown argument " + arg).c_str());
        }
    }
    if (!path)
        return usage("--socket is required");

    int lfd = socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un sa{};
    sa.sun_family = AF_UNIX;
    if (strlen(path) >= sizeof(sa.sun_path))
        return usage("socket path too long");
    strcpy(sa.sun_path, path);
    unlink(path);
    if (lfd < 0 || bind(lfd, reinterpret_cast<sockaddr *>(&sa), sizeof(sa)) || listen(lfd, 2)) {
        perror("enc_qei_server: socket");
        return 1;
    }

    Verilated::commandArgs(argc, argv);
    top = new Venc_qei_wb;
    channels = static_cast<int>(sizeof(top->a_in) * 8);
    uint32_t caps = 0;
    {
        // the number of channels and the architecture from CAPS, after reset
        top->rst = 1;
        for (int i = 0; i < 4; i++)
            tick();
        top->rst = 0;
        tick();
        access(4, false, &caps, 0xf);
        channels = static_cast<int>((caps >> 22) & 0x1f);
        if (channels < 1 || channels > kMaxChannels) {
            fprintf(stderr, "enc_qei_server: CAPS 0x%08x names %d channels\n", caps, channels);
            return 1;
        }
    }
    // the shared engine's bounds (CAPS.ENGINE, bit 31): see the top of this file
    const bool engine = caps >> 31;
    const int p = 24 * (channels > 2 ? channels : 2);
    const int settle_before = engine ? p + 22 : 0, settle_after = engine ? p + 44 : 0;
    if (engine)
        answer_bound = 6, after_write_bound = p + 66;
    save_rule = engine && (caps & 0xff) > 32 && channels > 1;  // CAPS.COUNT_W
    save_bound = p + 23;
    save_read_bound = p + 67;
    for (int k = 0; k < channels; k++)
        enc_stim_init(&stim[k], static_cast<unsigned>(k));
    drive_inputs();
    for (int i = 0; i < 64; i++)  // the input filters settle on the first state
        tick();
    const uint32_t addr_limit = 1u << ENC_QEI_ADDR_W;  // the bus port's byte-address bits

    printf("enc_qei_server: %d channels, %s, listening on %s\n", channels,
           engine ? "shared engine" : "per_channel", path);
    fflush(stdout);
    int bus = accept(lfd, nullptr, nullptr);
    int irq = accept(lfd, nullptr, nullptr);
    if (bus < 0 || irq < 0) {
        perror("enc_qei_server: accept");
        return 1;
    }
    bool irq_reported = false;
    uint64_t steps = 0, accesses = 0;
    for (;;) {
        uint32_t req[4], resp[2] = {0, 0};
        if (!full_io(bus, req, sizeof(req), true))
            break;
        if (req[0] == kOpRead || req[0] == kOpWrite) {
            uint32_t data = req[2];
            accesses++;
            if (req[1] >= addr_limit) {
                resp[1] = 1;
            } else {
                resp[1] = access(req[1], req[0] == kOpWrite, &data, req[3]);
                resp[0] = data;
            }
            if (req[0] == kOpRead && req[1] == 0 && id_override)
                resp[0] = id_word;
        } else if (req[0] == kOpAdvance) {
            for (int c = 0; c < settle_before; c++)
                tick();
            for (uint32_t i = 0; i < req[2]; i++) {
                for (int k = 0; k < channels; k++)
                    enc_stim_next(&stim[k]);
                drive_inputs();
                for (int c = 0; c < ENC_STIM_STEP_CLOCKS; c++)
                    tick();
            }
            for (int c = 0; c < settle_after; c++)
                tick();
            steps += req[2];
        } else {
            fprintf(stderr, "enc_qei_server: unknown request op %u\n", req[0]);
            return 1;
        }
        if (top->irq && !irq_reported) {
            char one = 1;
            if (!full_io(irq, &one, 1, false))
                break;
        }
        irq_reported = top->irq;
        if (!full_io(bus, resp, sizeof(resp), false))
            break;
    }
    printf("enc_qei_server: %llu accesses, %llu motion steps, %llu clocks; answers: the longest "
           "%d clocks after its request, %llu later than the bound of %d (%d from a write's "
           "request after it)\n",
           static_cast<unsigned long long>(accesses), static_cast<unsigned long long>(steps),
           static_cast<unsigned long long>(clocks), longest_answer,
           static_cast<unsigned long long>(late_answers), answer_bound, after_write_bound);
    top->final();
    delete top;
    unlink(path);
    return 0;
}
