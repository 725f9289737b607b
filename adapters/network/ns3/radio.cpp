// The C++ side of cosim's ns-3 radio (adapters/network/ns3), compiled at run time by cppyy
// in the radio's own process: ns-3 takes no Python callables for its callbacks or its
// scheduler, so everything that runs per event is here. WallLossModel subtracts a fixed
// loss per obstacle box the line between two nodes meets (chained after the log-distance
// model); RadioSim builds the 802.11 ad-hoc network, sends UDP broadcasts at
// exact nanoseconds with the message's id in their first 8 bytes, and records every
// reception (with the signal and SNR its PHY's monitor saw) and every frame a PHY dropped
// (with ns-3's reason), handed to Python in one copy per window.
#include <algorithm>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace cosim_ns3 {
using namespace ns3;

// ---------------------------------------------------------------------------
// Propagation loss model: subtracts lossDb per obstacle box (xmin, ymin, xmax, ymax) the
// straight line between the two nodes meets (a slab test, the same as
// models/network/shadowing.py boxes_crossed). Chained after LogDistance.
// ---------------------------------------------------------------------------
class WallLossModel : public PropagationLossModel
{
  public:
    static TypeId GetTypeId()
    {
        // Function-local static: registered once per process, lazily (cling does not run
        // namespace-scope static initialisers reliably, so no NS_OBJECT_ENSURE_REGISTERED).
        static TypeId tid = TypeId("cosim_ns3::WallLossModel")
                                .SetParent<PropagationLossModel>()
                                .SetGroupName("Propagation");
        return tid;
    }
    TypeId GetInstanceTypeId() const override { return GetTypeId(); }

    /// boxes = xmin,ymin,xmax,ymax, ...
    void SetWalls(const std::vector<double>& boxes, double lossDb)
    {
        if (boxes.size() % 4 != 0)
            throw std::invalid_argument("walls: length must be a multiple of 4");
        m_seg = boxes;
        m_lossDb = lossDb;
    }
    size_t NumWalls() const { return m_seg.size() / 4; }

    /// Number of boxes the segment (ax,ay)-(bx,by) meets.
    int Crossings(double ax, double ay, double bx, double by) const
    {
        int n = 0;
        const double p[2] = {ax, ay}, d[2] = {bx - ax, by - ay};
        for (size_t k = 0; k + 3 < m_seg.size(); k += 4)
        {
            double enter = 0.0, leave = 1.0;
            bool miss = false;
            for (int a = 0; a < 2 && !miss; ++a)
            {
                const double lo = m_seg[k + a], hi = m_seg[k + 2 + a];
                if (d[a] == 0.0)
                {
                    miss = p[a] < lo || p[a] > hi;
                    continue;
                }
                double t0 = (lo - p[a]) / d[a], t1 = (hi - p[a]) / d[a];
                if (t0 > t1)
                    std::swap(t0, t1);
                enter = std::max(enter, t0);
                leave = std::min(leave, t1);
            }
            if (!miss && enter <= leave)
                ++n;
        }
        return n;
    }

  private:
    double DoCalcRxPower(double txPowerDbm,
                         Ptr<MobilityModel> a,
                         Ptr<MobilityModel> b) const override
    {
        if (m_seg.empty())
            return txPowerDbm;
        const Vector pa = a->GetPosition();
        const Vector pb = b->GetPosition();
        return txPowerDbm - m_lossDb * Crossings(pa.x, pa.y, pb.x, pb.y);
    }
    int64_t DoAssignStreams(int64_t) override { return 0; }

    std::vector<double> m_seg;
    double m_lossDb{0.0};
};

// ---------------------------------------------------------------------------
// Records (packed, mirrored by numpy dtypes in radio.py)
// ---------------------------------------------------------------------------
struct RxRecord
{
    int64_t t_ns;     // application receive time
    int64_t msg_id;   // payload bytes 0..7
    int32_t rx;       // receiver node index
    int32_t tx;       // sender node index
    double rssi_dbm;  // MonitorSnifferRx signal of the (last) frame; NaN if unknown
    double snr_db;    // signal - noise(+interference) from MonitorSnifferRx; NaN if unknown
};
static_assert(sizeof(RxRecord) == 40, "RxRecord layout");

struct DropRecord
{
    int64_t t_ns;     // time of the PhyRxDrop trace
    int64_t msg_id;   // parsed from the frame (-1 if not a first UDP fragment)
    int32_t rx;       // node whose PHY dropped the frame
    int32_t tx;       // transmitter (MAC Addr2), -1 if unknown
    int32_t reason;   // ns3::WifiPhyRxfailureReason
    int32_t frag;     // IPv4 fragment offset in bytes (-1 if not IPv4)
};
static_assert(sizeof(DropRecord) == 32, "DropRecord layout");

struct RadioConfig
{
    uint32_t n_nodes = 2;
    std::string standard = "80211g";   // 80211g | 80211n | 80211p | 80211a
    std::string rate = "ErpOfdmRate6Mbps";
    std::string channel_settings = ""; // e.g. "{1, 20, BAND_2_4GHZ, 0}"; "" = default
    double tx_power_dbm = 20.0;
    double exponent = 3.0;
    double reference_loss_db = 40.05;   // free space at 1 m, 2.4 GHz
    double reference_distance_m = 1.0;
    bool nakagami = false;
    double nakagami_m0 = 1.5, nakagami_m1 = 0.75, nakagami_m2 = 0.75;
    double nakagami_d1 = 80.0, nakagami_d2 = 200.0;
    double rx_sensitivity_dbm = -101.0;   // YansWifiPhy RxSensitivity
    double preamble_min_rssi_dbm = -82.0; // ThresholdPreambleDetectionModel MinimumRssi
    double preamble_threshold_db = 4.0;   // ThresholdPreambleDetectionModel Threshold (SNR)
    double cca_ed_threshold_dbm = -62.0;  // WifiPhy CcaEdThreshold
    std::vector<double> walls;            // flat xmin,ymin,xmax,ymax boxes
    double wall_loss_db = 10.0;
    uint32_t seed = 1;
    uint64_t run = 1;
    uint16_t port = 9;
    bool populate_arp = true;             // NeighborCacheHelper (needed for unicast)
};

// ---------------------------------------------------------------------------
// The simulation
// ---------------------------------------------------------------------------
class RadioSim
{
  public:
    RadioSim() = default;
    ~RadioSim() { Release(); }

    void Setup(const RadioConfig& c)
    {
        if (m_setup)
            throw std::logic_error("RadioSim already set up");
        if (c.n_nodes < 1)
            throw std::invalid_argument("n_nodes must be >= 1");
        m_cfg = c;
        // Global state left by a previous simulation in this process.
        Simulator::Destroy();
        RngSeedManager::ResetNextStreamIndex();
        Ipv4AddressGenerator::Reset();
        Mac48Address::ResetAllocationIndex();
        RngSeedManager::SetSeed(c.seed);
        RngSeedManager::SetRun(c.run);

        m_nodes.Create(c.n_nodes);
        m_nodeBase = m_nodes.Get(0)->GetId();
        for (uint32_t i = 0; i < c.n_nodes; ++i)
        {
            Ptr<ConstantPositionMobilityModel> mm = CreateObject<ConstantPositionMobilityModel>();
            mm->SetPosition(Vector(0, 0, 0));
            m_nodes.Get(i)->AggregateObject(mm);
            m_mob.push_back(mm);
        }

        // Channel: LogDistance -> WallLoss -> [Nakagami]
        Ptr<YansWifiChannel> chan = CreateObject<YansWifiChannel>();
        chan->SetPropagationDelayModel(CreateObject<ConstantSpeedPropagationDelayModel>());
        Ptr<LogDistancePropagationLossModel> logd = CreateObject<LogDistancePropagationLossModel>();
        logd->SetAttribute("Exponent", DoubleValue(c.exponent));
        logd->SetAttribute("ReferenceLoss", DoubleValue(c.reference_loss_db));
        logd->SetAttribute("ReferenceDistance", DoubleValue(c.reference_distance_m));
        m_walls = CreateObject<WallLossModel>();
        m_walls->SetWalls(c.walls, c.wall_loss_db);
        logd->SetNext(m_walls);
        if (c.nakagami)
        {
            Ptr<NakagamiPropagationLossModel> nk = CreateObject<NakagamiPropagationLossModel>();
            nk->SetAttribute("m0", DoubleValue(c.nakagami_m0));
            nk->SetAttribute("m1", DoubleValue(c.nakagami_m1));
            nk->SetAttribute("m2", DoubleValue(c.nakagami_m2));
            nk->SetAttribute("Distance1", DoubleValue(c.nakagami_d1));
            nk->SetAttribute("Distance2", DoubleValue(c.nakagami_d2));
            m_walls->SetNext(nk);
        }
        chan->SetPropagationLossModel(logd);
        m_chan = chan;
        m_loss = logd;

        WifiHelper wifi;
        if (c.standard == "80211g")
            wifi.SetStandard(WIFI_STANDARD_80211g);
        else if (c.standard == "80211n")
            wifi.SetStandard(WIFI_STANDARD_80211n);
        else if (c.standard == "80211p")
            wifi.SetStandard(WIFI_STANDARD_80211p);
        else if (c.standard == "80211a")
            wifi.SetStandard(WIFI_STANDARD_80211a);
        else
            throw std::invalid_argument("unknown standard " + c.standard);
        // The rate is set after Install (below), once we can check it against
        // the PHY's mode list: an unknown WifiMode name given as a StringValue
        // is an NS_FATAL_ERROR (process abort) inside ns-3.
        wifi.SetRemoteStationManager("ns3::ConstantRateWifiManager");

        YansWifiPhyHelper phy;
        phy.SetChannel(chan);
        std::string cs = c.channel_settings;
        if (cs.empty() && c.standard == "80211n")
            cs = "{1, 20, BAND_2_4GHZ, 0}"; // 802.11n defaults to 5 GHz otherwise
        if (!cs.empty())
            phy.Set("ChannelSettings", StringValue(cs));
        phy.Set("TxPowerStart", DoubleValue(c.tx_power_dbm));
        phy.Set("TxPowerEnd", DoubleValue(c.tx_power_dbm));
        phy.Set("TxPowerLevels", UintegerValue(1));
        phy.Set("RxSensitivity", DoubleValue(c.rx_sensitivity_dbm));
        phy.Set("CcaEdThreshold", DoubleValue(c.cca_ed_threshold_dbm));
        phy.SetPreambleDetectionModel("ns3::ThresholdPreambleDetectionModel",
                                      "MinimumRssi", DoubleValue(c.preamble_min_rssi_dbm),
                                      "Threshold", DoubleValue(c.preamble_threshold_db));

        WifiMacHelper mac;
        mac.SetType("ns3::AdhocWifiMac");
        m_devs = wifi.Install(phy, mac, m_nodes);
        {
            Ptr<WifiPhy> p0 = DynamicCast<WifiNetDevice>(m_devs.Get(0))->GetPhy();
            std::set<std::string> names;
            for (const auto& l : {p0->GetModeList(), p0->GetMcsList()})
                for (const WifiMode& m : l)
                    names.insert(m.GetUniqueName());
            const bool ok = names.count(c.rate) > 0;
            std::string known;
            for (const auto& n : names)
                known += " " + n;
            if (!ok)
            {
                Simulator::Destroy();
                m_nodes = NodeContainer();
                m_devs = NetDeviceContainer();
                m_mob.clear();
                throw std::invalid_argument("rate " + c.rate + " not supported by " + c.standard +
                                            "; known:" + known);
            }
            for (uint32_t i = 0; i < c.n_nodes; ++i)
            {
                Ptr<WifiRemoteStationManager> rsm =
                    DynamicCast<WifiNetDevice>(m_devs.Get(i))->GetRemoteStationManager();
                rsm->SetAttribute("DataMode", StringValue(c.rate));
                rsm->SetAttribute("ControlMode", StringValue(c.rate));
                // Broadcast/multicast frames do NOT use DataMode: they use
                // WifiRemoteStationManager::NonUnicastMode, which defaults to
                // the PHY's first mode (DSSS 1 Mbps for 802.11g!).
                rsm->SetAttribute("NonUnicastMode", StringValue(c.rate));
            }
        }

        InternetStackHelper inet;
        inet.Install(m_nodes);
        Ipv4AddressHelper ip;
        ip.SetBase("10.0.0.0", "255.255.0.0"); // up to 65534 nodes
        m_ifaces = ip.Assign(m_devs);

        // Fixed stream numbers -> reproducible independent of object creation order.
        int64_t s = 100;
        s += WifiHelper::AssignStreams(m_devs, s);
        s += chan->AssignStreams(s);
        s += inet.AssignStreams(m_nodes, s);

        if (c.populate_arp)
            NeighborCacheHelper().PopulateNeighborCache(m_ifaces);

        for (uint32_t i = 0; i < c.n_nodes; ++i)
        {
            m_ipToIdx[m_ifaces.GetAddress(i).Get()] = i;
            m_macToIdx[Mac48Address::ConvertFrom(m_devs.Get(i)->GetAddress())] = i;

            Ptr<Socket> sk = Socket::CreateSocket(m_nodes.Get(i), UdpSocketFactory::GetTypeId());
            sk->SetAllowBroadcast(true);
            if (sk->Bind(InetSocketAddress(Ipv4Address::GetAny(), c.port)) != 0)
                throw std::runtime_error("socket bind failed");
            sk->SetRecvCallback(MakeCallback(&RadioSim::OnRecv, this));
            m_socks.push_back(sk);

            Ptr<WifiPhy> wphy = DynamicCast<WifiNetDevice>(m_devs.Get(i))->GetPhy();
            bool ok = wphy->TraceConnectWithoutContext(
                "MonitorSnifferRx", MakeBoundCallback(&RadioSim::SniffRx, this, i));
            ok &= wphy->TraceConnectWithoutContext(
                "PhyRxDrop", MakeBoundCallback(&RadioSim::PhyDrop, this, i));
            // Sender-side MAC drops (queue full, MSDU lifetime 500 ms expired, retries).
            ok &= DynamicCast<WifiNetDevice>(m_devs.Get(i))->GetMac()->TraceConnectWithoutContext(
                "DroppedMpdu", MakeBoundCallback(&RadioSim::MacDrop, this));
            // IP drops (e.g. DROP_FRAGMENT_TIMEOUT when a fragment of a large datagram is lost).
            ok &= m_nodes.Get(i)->GetObject<Ipv4L3Protocol>()->TraceConnectWithoutContext(
                "Drop", MakeBoundCallback(&RadioSim::IpDrop, this));
            if (!ok)
                throw std::runtime_error("a trace source could not be connected");
        }
        m_lastRssi.assign(c.n_nodes, std::nan(""));
        m_lastSnr.assign(c.n_nodes, std::nan(""));
        m_lastSniffNs.assign(c.n_nodes, -1);
        m_setup = true;
    }

    // ---- mobility -------------------------------------------------------
    void SetPositions(uintptr_t xyPtr, int64_t n, int64_t ncols)
    {
        CheckSetup();
        if (n != (int64_t)m_mob.size())
            throw std::invalid_argument("set_positions: need one row per node");
        if (ncols != 2 && ncols != 3)
            throw std::invalid_argument("set_positions: need 2 or 3 columns");
        const double* xy = reinterpret_cast<const double*>(xyPtr);
        for (int64_t i = 0; i < n; ++i)
            m_mob[i]->SetPosition(Vector(xy[i * ncols], xy[i * ncols + 1],
                                         ncols == 3 ? xy[i * ncols + 2] : 0.0));
    }
    int WallCrossings(int32_t a, int32_t b) const
    {
        CheckNode(a); CheckNode(b);
        Vector pa = m_mob[a]->GetPosition(), pb = m_mob[b]->GetPosition();
        return m_walls->Crossings(pa.x, pa.y, pb.x, pb.y);
    }
    /// Mean received power (dBm) from a to b through the deterministic part of
    /// the chain (LogDistance + walls), i.e. without Nakagami.
    double MeanRxPowerDbm(int32_t a, int32_t b) const
    {
        CheckNode(a); CheckNode(b);
        double p = m_cfg.tx_power_dbm;
        // Call the two deterministic models directly (skip Nakagami).
        Ptr<PropagationLossModel> next = m_walls->GetNext();
        m_walls->SetNext(nullptr);
        double r = m_loss->CalcRxPower(p, m_mob[a], m_mob[b]);
        m_walls->SetNext(next);
        return r;
    }

    // ---- sending --------------------------------------------------------
    /// Schedule node `src` to send `nbytes` with id `msgId` at absolute t_ns.
    /// dst < 0: broadcast; else unicast to node dst.
    void Send(int64_t tNs, int32_t src, int64_t msgId, int32_t nbytes, int32_t dst)
    {
        CheckSetup();
        CheckNode(src);
        if (dst >= 0) CheckNode(dst);
        if (nbytes < 8 || nbytes > 65507)
            throw std::invalid_argument("nbytes must be in [8, 65507]");
        const int64_t now = Simulator::Now().GetNanoSeconds();
        if (tNs < now)
            throw std::invalid_argument("send time " + std::to_string(tNs) +
                                        " ns is before now " + std::to_string(now) + " ns");
        Simulator::ScheduleWithContext(m_nodeBase + src, NanoSeconds(tNs - now),
                                       &RadioSim::DoSend, this, src, msgId, nbytes, dst);
        ++m_nScheduled;
    }
    /// Vectorised Send: arrays of n int64 t, int32 src, int64 id, int32 nbytes, int32 dst.
    void SendMany(uintptr_t t, uintptr_t src, uintptr_t id, uintptr_t nb, uintptr_t dst, int64_t n)
    {
        const int64_t* T = reinterpret_cast<const int64_t*>(t);
        const int32_t* S = reinterpret_cast<const int32_t*>(src);
        const int64_t* I = reinterpret_cast<const int64_t*>(id);
        const int32_t* B = reinterpret_cast<const int32_t*>(nb);
        const int32_t* D = reinterpret_cast<const int32_t*>(dst);
        // Validate everything first so that a bad batch schedules nothing.
        CheckSetup();
        const int64_t now = Simulator::Now().GetNanoSeconds();
        for (int64_t k = 0; k < n; ++k)
        {
            CheckNode(S[k]);
            if (D[k] >= 0) CheckNode(D[k]);
            if (B[k] < 8 || B[k] > 65507)
                throw std::invalid_argument("nbytes must be in [8, 65507] (item " + std::to_string(k) + ")");
            if (T[k] < now)
                throw std::invalid_argument("send time before now (item " + std::to_string(k) + ")");
        }
        for (int64_t k = 0; k < n; ++k)
            Send(T[k], S[k], I[k], B[k], D[k]);
    }
    /// For tests of the containment only: schedule with an unchecked (possibly negative)
    /// delay, so that ns-3's own NS_ASSERT fires and aborts the process.
    void UncheckedScheduleSend(int64_t tNs, int32_t src)
    {
        const int64_t now = Simulator::Now().GetNanoSeconds();
        Simulator::Schedule(NanoSeconds(tNs - now), &RadioSim::DoSend, this, src, (int64_t)-1, 100, -1);
    }

    // ---- running --------------------------------------------------------
    void RunUntil(int64_t tNs)
    {
        CheckSetup();
        const int64_t now = Simulator::Now().GetNanoSeconds();
        if (tNs < now)
            throw std::invalid_argument("run_until " + std::to_string(tNs) + " ns is before now " +
                                        std::to_string(now) + " ns");
        // a reception may stop the run first (SetStopOnRx): the stop at tNs must not outlive it
        EventId stop = Simulator::Stop(NanoSeconds(tNs - now));
        Simulator::Run();
        Simulator::Cancel(stop);
    }
    /// Stop every run at the first reception (the exact mode's step), or not.
    void SetStopOnRx(bool on) { m_stopOnRx = on; }
    int64_t NowNs() const { return Simulator::Now().GetNanoSeconds(); }

    // ---- draining records -------------------------------------------------
    int64_t NumRx() const { return (int64_t)m_rx.size(); }
    int64_t NumDrop() const { return (int64_t)m_drop.size(); }
    /// Copy all pending records to `out` (caller allocated, NumRx()*40 bytes) and clear.
    void DrainRx(uintptr_t out)
    {
        if (!m_rx.empty())
            std::memcpy(reinterpret_cast<void*>(out), m_rx.data(), m_rx.size() * sizeof(RxRecord));
        m_rx.clear();
    }
    void DrainDrop(uintptr_t out)
    {
        if (!m_drop.empty())
            std::memcpy(reinterpret_cast<void*>(out), m_drop.data(), m_drop.size() * sizeof(DropRecord));
        m_drop.clear();
    }
    int64_t NumSendFailures() const { return m_sendFail; }
    /// Counters: MAC drops by WifiMacDropReason (0..3), IP drops by Ipv4L3Protocol::DropReason (0..7).
    int64_t MacDrops(int reason) const { return (reason >= 0 && reason < 4) ? m_macDrops[reason] : 0; }
    int64_t IpDrops(int reason) const { return (reason >= 0 && reason < 8) ? m_ipDrops[reason] : 0; }
    int64_t NumScheduled() const { return m_nScheduled; }
    int64_t NumSent() const { return m_nSent; }

    /// Destroy the simulator and drop all references (safe to call twice).
    void Release()
    {
        if (!m_setup)
            return;
        for (auto& s : m_socks)
            s->SetRecvCallback(MakeNullCallback<void, Ptr<Socket>>());
        m_socks.clear();
        Simulator::Destroy();
        m_mob.clear();
        m_devs = NetDeviceContainer();
        m_ifaces = Ipv4InterfaceContainer();
        m_nodes = NodeContainer();
        m_walls = nullptr;
        m_loss = nullptr;
        m_chan = nullptr;
        m_setup = false;
    }

    static std::string ReasonName(int r)
    {
        // NB: ns-3's operator<< calls NS_FATAL_ERROR for UNKNOWN (0) and
        // out-of-range values, so guard it.
        if (r <= (int)UNKNOWN || r > (int)SIGNAL_DETECTION_ABORTED_BY_TX)
            return r == 0 ? "UNKNOWN" : "INVALID";
        std::ostringstream os;
        os << static_cast<WifiPhyRxfailureReason>(r);
        return os.str();
    }
  private:
    void CheckSetup() const
    {
        if (!m_setup) throw std::logic_error("RadioSim not set up");
    }
    void CheckNode(int32_t i) const
    {
        if (i < 0 || i >= (int32_t)m_mob.size())
            throw std::out_of_range("node index " + std::to_string(i) + " out of range [0, " +
                                    std::to_string(m_mob.size()) + ")");
    }

    void DoSend(int32_t src, int64_t msgId, int32_t nbytes, int32_t dst)
    {
        m_buf.assign(nbytes, 0);
        std::memcpy(m_buf.data(), &msgId, 8);
        Ptr<Packet> p = Create<Packet>(m_buf.data(), nbytes);
        Ipv4Address to = dst < 0 ? Ipv4Address("255.255.255.255") : m_ifaces.GetAddress(dst);
        if (m_socks[src]->SendTo(p, 0, InetSocketAddress(to, m_cfg.port)) < 0)
            ++m_sendFail;
        else
            ++m_nSent;
    }

    void OnRecv(Ptr<Socket> sk)
    {
        const int32_t rx = (int32_t)(sk->GetNode()->GetId() - m_nodeBase);
        const int64_t now = Simulator::Now().GetNanoSeconds();
        Address from;
        Ptr<Packet> p;
        while ((p = sk->RecvFrom(from)))
        {
            RxRecord r;
            r.t_ns = now;
            r.msg_id = -1;
            if (p->GetSize() >= 8)
                p->CopyData(reinterpret_cast<uint8_t*>(&r.msg_id), 8);
            r.rx = rx;
            auto it = m_ipToIdx.find(InetSocketAddress::ConvertFrom(from).GetIpv4().Get());
            r.tx = it == m_ipToIdx.end() ? -1 : (int32_t)it->second;
            // The sniffer fires in the same event just before the frame is
            // forwarded up, so the last sniffed values belong to this frame
            // (for a fragmented datagram: to its last fragment).
            const bool fresh = m_lastSniffNs[rx] == now;
            r.rssi_dbm = fresh ? m_lastRssi[rx] : std::nan("");
            r.snr_db = fresh ? m_lastSnr[rx] : std::nan("");
            m_rx.push_back(r);
        }
        if (m_stopOnRx)
            Simulator::Stop();
    }

    static void SniffRx(RadioSim* self, uint32_t node, Ptr<const Packet>, uint16_t,
                        WifiTxVector, MpduInfo, SignalNoiseDbm sn, uint16_t)
    {
        self->m_lastRssi[node] = sn.signal;
        self->m_lastSnr[node] = sn.signal - sn.noise;
        self->m_lastSniffNs[node] = Simulator::Now().GetNanoSeconds();
    }

    static void PhyDrop(RadioSim* self, uint32_t node, Ptr<const Packet> pkt,
                        WifiPhyRxfailureReason reason)
    {
        DropRecord d;
        d.t_ns = Simulator::Now().GetNanoSeconds();
        d.msg_id = -1;
        d.rx = (int32_t)node;
        d.tx = -1;
        d.reason = (int32_t)reason;
        d.frag = -1;
        if (pkt)
            self->ParseFrame(pkt, d);
        self->m_drop.push_back(d);
    }

    static void MacDrop(RadioSim* self, WifiMacDropReason reason, Ptr<const WifiMpdu>)
    {
        if ((int)reason < 4) ++self->m_macDrops[(int)reason];
    }
    static void IpDrop(RadioSim* self, const Ipv4Header&, Ptr<const Packet>,
                       Ipv4L3Protocol::DropReason reason, Ptr<Ipv4>, uint32_t)
    {
        if ((int)reason < 8) ++self->m_ipDrops[(int)reason];
    }

    /// Best-effort parse of MAC/LLC/IPv4/UDP headers of a dropped MPDU.
    void ParseFrame(Ptr<const Packet> pkt, DropRecord& d) const
    {
        Ptr<Packet> p = pkt->Copy();
        WifiMacHeader mh;
        if (p->GetSize() < mh.GetSerializedSize()) return;
        p->RemoveHeader(mh);
        auto it = m_macToIdx.find(mh.GetAddr2());
        if (it != m_macToIdx.end()) d.tx = (int32_t)it->second;
        if (!mh.IsData()) return;
        LlcSnapHeader llc;
        if (p->GetSize() < llc.GetSerializedSize()) return;
        p->RemoveHeader(llc);
        if (llc.GetType() != 0x0800) return;
        Ipv4Header iph;
        if (p->GetSize() < 20) return;
        p->RemoveHeader(iph);
        d.frag = iph.GetFragmentOffset();
        if (iph.GetFragmentOffset() != 0 || iph.GetProtocol() != 17) return;
        UdpHeader uh;
        if (p->GetSize() < 8 + 8) return;
        p->RemoveHeader(uh);
        int64_t id;
        p->CopyData(reinterpret_cast<uint8_t*>(&id), 8);
        d.msg_id = id;
    }

    bool m_setup{false};
    bool m_stopOnRx{false};
    RadioConfig m_cfg;
    NodeContainer m_nodes;
    uint32_t m_nodeBase{0};
    NetDeviceContainer m_devs;
    Ipv4InterfaceContainer m_ifaces;
    std::vector<Ptr<ConstantPositionMobilityModel>> m_mob;
    std::vector<Ptr<Socket>> m_socks;
    Ptr<YansWifiChannel> m_chan;
    Ptr<LogDistancePropagationLossModel> m_loss;
    Ptr<WallLossModel> m_walls;
    std::map<uint32_t, uint32_t> m_ipToIdx;
    std::map<Mac48Address, uint32_t> m_macToIdx;
    std::vector<double> m_lastRssi, m_lastSnr;
    std::vector<int64_t> m_lastSniffNs;
    std::vector<RxRecord> m_rx;
    std::vector<DropRecord> m_drop;
    std::vector<uint8_t> m_buf;
    int64_t m_sendFail{0}, m_nScheduled{0}, m_nSent{0};
    int64_t m_macDrops[4]{0, 0, 0, 0};
    int64_t m_ipDrops[8]{0, 0, 0, 0, 0, 0, 0, 0};
};

} // namespace cosim_ns3
