moreau::model! {
    pub struct Ball;
    coordinates { x: vx, y: vy }
    let lookahead = y + 0.01 * vy;
    kinetic = 0.5 * (vx^2 + vy^2);
    constraints { floor: lookahead >= 0 }
    restitution = 0.5;
}

fn main() {}
