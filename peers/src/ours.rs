//! ballpit itself as an engine of the harness, for `--interleave`: the scene loaded into a
//! headless app as `ballpit run` loads it (its own collision mode, the continuous one unless
//! the scene says otherwise; one thread; the counters only), a step an `update()`. So its steps
//! and Box2D's can be timed in turn in one process, each engine's step next to the other's.

use ballpit::commands::observe::dump::StateDump;
use ballpit::headless::{counters_only, headless_app_with_threads};
use ballpit::sim::SceneSetup;
use bevy::app::App;
use bevy::math::DVec2;

use crate::Engine;
use crate::scene::{Ball, Scene};

pub struct Ballpit {
    app: App,
    /// Half the arena: ballpit's centred coordinates to the harness's.
    half: DVec2,
}

impl Ballpit {
    /// The scene's setup in a fresh app with one thread at work (the compute pool has no
    /// worker); the first app of the process sets the pools, so make this one first.
    pub fn new(scene: &Scene, setup: &SceneSetup) -> Ballpit {
        let mut app = headless_app_with_threads(scene.dt, Some(1));
        counters_only(&mut app);
        setup.apply(app.world_mut());
        Ballpit {
            app,
            half: scene.size / 2.0,
        }
    }
}

impl Engine for Ballpit {
    fn step(&mut self) {
        self.app.update();
    }

    fn balls(&mut self) -> Vec<Ball> {
        let dump = StateDump::capture(self.app.world_mut());
        (dump.balls.iter())
            .map(|ball| Ball {
                position: DVec2::new(ball.x, ball.y) + self.half,
                velocity: DVec2::new(ball.vx, ball.vy),
                radius: ball.r,
            })
            .collect()
    }
}
