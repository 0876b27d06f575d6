// fastdds_cmd_vel.cpp - an independent DDS subscriber of /cmd_vel: eProsima
// Fast DDS (Debian's libfastrtps-dev), its Twist type made by fastddsgen
// from spvs_msgs/external/geometry_msgs/msg/Twist.idl, the IDL Cyclone DDS's
// idlc compiles for spvs-node.
//
//   fastdds_cmd_vel OUT MAX_S
// Subscribes the DDS topic rt/cmd_vel (type geometry_msgs::msg::dds_::Twist_)
// on $ROS_DOMAIN_ID, reliable, keeping every sample, and writes one line per
// Twist to OUT: "T t lx ly lz ax ay az" (t: seconds since start).  Writes
// OUT.ready once a writer is matched.  Leaves after MAX_S s or on SIGTERM.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "TwistPubSubTypes.h"

using namespace eprosima::fastdds::dds;

static std::atomic<bool> g_stop(false);
static void on_signal(int) { g_stop = true; }

static double now_s()
{
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
}

class Listener : public DataReaderListener {
public:
    Listener(FILE *out, std::string ready, double t0)
        : out_(out), ready_(std::move(ready)), t0_(t0) {}

    void on_subscription_matched(DataReader *,
                                 const SubscriptionMatchedStatus &info) override
    {
        if (info.current_count > 0) {
            FILE *r = std::fopen(ready_.c_str(), "w");
            if (r)
                std::fclose(r);
        }
    }

    void on_data_available(DataReader *reader) override
    {
        geometry_msgs::msg::dds_::Twist_ tw;
        SampleInfo info;
        while (reader->take_next_sample(&tw, &info) == ReturnCode_t::RETCODE_OK) {
            if (!info.valid_data)
                continue;
            std::fprintf(out_, "T %.6f %.17g %.17g %.17g %.17g %.17g %.17g\n",
                         now_s() - t0_, tw.linear().x(), tw.linear().y(),
                         tw.linear().z(), tw.angular().x(), tw.angular().y(),
                         tw.angular().z());
            std::fflush(out_);
        }
    }

private:
    FILE *out_;
    std::string ready_;
    double t0_;
};

int main(int argc, char **argv)
{
    if (argc != 3) {
        std::fprintf(stderr, "usage: fastdds_cmd_vel OUT MAX_S\n");
        return 2;
    }
    const char *d = std::getenv("ROS_DOMAIN_ID");
    int domain = d && *d ? std::atoi(d) : 0;
    double max_s = std::atof(argv[2]);
    std::signal(SIGTERM, on_signal);
    std::signal(SIGINT, on_signal);
    FILE *out = std::fopen(argv[1], "w");
    if (!out) {
        std::perror(argv[1]);
        return 1;
    }
    double t0 = now_s();

    DomainParticipant *pp = DomainParticipantFactory::get_instance()
        ->create_participant(domain, PARTICIPANT_QOS_DEFAULT);
    if (!pp) {
        std::fprintf(stderr, "fastdds_cmd_vel: no participant on domain %d\n", domain);
        return 1;
    }
    TypeSupport type(new geometry_msgs::msg::dds_::Twist_PubSubType());
    type.register_type(pp);
    Topic *topic = pp->create_topic("rt/cmd_vel", type.get_type_name(),
                                    TOPIC_QOS_DEFAULT);
    Subscriber *sub = pp->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
    DataReaderQos rq = DATAREADER_QOS_DEFAULT;
    rq.reliability().kind = RELIABLE_RELIABILITY_QOS;
    rq.durability().kind = VOLATILE_DURABILITY_QOS;
    rq.history().kind = KEEP_ALL_HISTORY_QOS;
    std::string ready = std::string(argv[1]) + ".ready";
    Listener listener(out, ready, t0);
    DataReader *reader = topic && sub ? sub->create_datareader(topic, rq, &listener) : nullptr;
    if (!reader) {
        std::fprintf(stderr, "fastdds_cmd_vel: cannot create the reader\n");
        return 1;
    }
    std::fprintf(stderr, "fastdds_cmd_vel: domain %d, rt/cmd_vel as %s\n",
                 domain, type.get_type_name().c_str());
    while (!g_stop && now_s() - t0 < max_s)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));

    sub->delete_datareader(reader);
    pp->delete_subscriber(sub);
    pp->delete_topic(topic);
    DomainParticipantFactory::get_instance()->delete_participant(pp);
    std::fclose(out);
    return 0;
}
