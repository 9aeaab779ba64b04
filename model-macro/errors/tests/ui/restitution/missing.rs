moreau::model! {
    pub struct Ball;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2;
    constraints { floor: y >= 0, #[restitution = 0.8] ceiling: y <= 2 }
}

fn main() {}
