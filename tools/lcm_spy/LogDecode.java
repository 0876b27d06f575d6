// LogDecode LOG: decodes every event of an LCM log the way lcm-spy does
// (lcm.spy.LCMTypeDatabase finds the message classes on the class path by
// their fingerprint) and prints, per channel, the class and the count of
// events decoded and not decoded, then the last spvs.cmd_t that answers a frame (seq >= 0).  Used by
// tools/lcm_spy/check.sh to show which types lcm-spy will show.
import java.io.ByteArrayInputStream;
import java.io.DataInputStream;
import java.io.EOFException;
import java.io.IOException;
import java.util.Map;
import java.util.TreeMap;

import lcm.logging.Log;
import lcm.spy.LCMTypeDatabase;

public class LogDecode {
    public static void main(String[] args) throws Exception {
        if (args.length != 1) {
            System.err.println("usage: LogDecode LOG");
            System.exit(2);
        }
        LCMTypeDatabase db = new LCMTypeDatabase();
        Map<String, String> type = new TreeMap<>();
        Map<String, Integer> ok = new TreeMap<>(), bad = new TreeMap<>();
        Object lastCmd = null;
        Log log = new Log(args[0], "r");
        while (true) {
            Log.Event ev;
            try {
                ev = log.readNext();
            } catch (EOFException e) {
                break;
            }
            Object msg = null;
            if (ev.data.length >= 8) {
                long fp = new DataInputStream(new ByteArrayInputStream(ev.data)).readLong();
                Class<?> cls = db.getClassByFingerprint(fp);
                if (cls != null) {
                    try {
                        msg = cls.getConstructor(byte[].class).newInstance((Object) ev.data);
                    } catch (Exception e) {
                        msg = null;
                    }
                }
            }
            if (msg == null) {
                bad.merge(ev.channel, 1, Integer::sum);
                type.putIfAbsent(ev.channel, "-");
                continue;
            }
            ok.merge(ev.channel, 1, Integer::sum);
            type.put(ev.channel, msg.getClass().getName());
            if (msg instanceof spvs.cmd_t && ((spvs.cmd_t) msg).seq >= 0) {
                lastCmd = msg;
            }
        }
        log.close();
        for (String ch : type.keySet()) {
            System.out.printf("channel %s %s decoded %d undecodable %d%n", ch, type.get(ch),
                              ok.getOrDefault(ch, 0), bad.getOrDefault(ch, 0));
        }
        if (lastCmd != null) {
            spvs.cmd_t c = (spvs.cmd_t) lastCmd;
            System.out.printf("last_cmd seq %d step %d status %d v %.6f w %.6f%n", c.seq, c.step,
                              c.status, c.v, c.w);
        }
    }
}
