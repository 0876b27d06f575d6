// Click X Y [N]: clicks the left mouse button N times (default 2, a
// double-click) at screen position (X, Y) of $DISPLAY, through the X test
// extension (java.awt.Robot).  spy_replay.sh uses it to open lcm-spy's
// viewer of one channel for the screenshot.
import java.awt.Robot;
import java.awt.event.InputEvent;

public class Click {
    public static void main(String[] args) throws Exception {
        if (args.length < 2 || args.length > 3) {
            System.err.println("usage: Click X Y [N]");
            System.exit(2);
        }
        int x = Integer.parseInt(args[0]), y = Integer.parseInt(args[1]);
        int n = args.length == 3 ? Integer.parseInt(args[2]) : 2;
        Robot r = new Robot();
        r.setAutoDelay(40);
        r.mouseMove(x, y);
        for (int i = 0; i < n; i++) {
            r.mousePress(InputEvent.BUTTON1_DOWN_MASK);
            r.mouseRelease(InputEvent.BUTTON1_DOWN_MASK);
        }
        r.waitForIdle();
    }
}
